// What a photo's EXIF records that a burst read from files needs: the focal length, for motion
// estimation, and the orientation, carried into the refocused photo.
#pragma once

#include <cstdint>

namespace lb {

// Focal length in px of a width x height image from the file's EXIF FocalLengthIn35mmFilm (the
// 35 mm equivalent, defined on the 43.27 mm diagonal of a 36 x 24 mm frame), or 0 when the file
// has no EXIF or no such tag (PNG and PPM files, most edited JPEGs).
double ExifFocalPx(const char* path, int32_t width, int32_t height);

// The file's EXIF Orientation (1..8: how a viewer should turn the stored pixels), or 0 when it
// records none.
int32_t ExifOrientation(const char* path);

}  // namespace lb
