// EXIF (libexif): the block the product writes into its photos, and the two tags it reads from
// the frames it is given (and from its own photos on a re-render).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "algo/core/status.h"

namespace lb {

// The tags the product records. Zero or empty = not recorded.
struct ExifTags {
  std::string make;
  std::string model;
  std::string software;
  std::string datetime_original;  // "YYYY:MM:DD HH:MM:SS"
  float f_number = 0.0f;
  int32_t focal_35mm = 0;   // 35 mm equivalent focal length, mm
  int32_t orientation = 0;  // EXIF Orientation 1..8

  // True when any tag above is set: only then is an EXIF block written.
  bool has_exif() const;
};

// Builds the EXIF APP1 payload ("Exif\0\0" + TIFF) for a width x height image, with the tags
// EXIF 2.3 requires in a JPEG besides those asked for.
Status BuildExif(const ExifTags& tags, int32_t width, int32_t height,
                 std::vector<uint8_t>* payload);

// Focal length in px of a width x height image from the file's EXIF FocalLengthIn35mmFilm (the
// 35 mm equivalent, defined on the 43.27 mm diagonal of a 36 x 24 mm frame), or 0 when the file
// has no EXIF or no such tag (PNG and PPM files, most edited JPEGs).
double ExifFocalPx(const char* path, int32_t width, int32_t height);

// The file's EXIF Orientation (1..8: how a viewer should turn the stored pixels), or 0 when it
// records none.
int32_t ExifOrientation(const char* path);
// The same from a whole file already in memory.
int32_t ExifOrientation(const uint8_t* data, size_t size);
// The same from an open file (borrowed; read from its start with pread, so where it stands does
// not move), read only as far as its EXIF segment.
int32_t ExifOrientationAt(int fd);

// How a viewer turns the stored pixels for EXIF Orientation `o`, on points given as fractions
// of the image's sides: stored (s, t) -> displayed (u, v), and back. Orientations outside 1..8
// (0: none recorded) leave points as stored.
void ExifStoredToDisplayed(int32_t o, double s, double t, double* u, double* v);
void ExifDisplayedToStored(int32_t o, double u, double v, double* s, double* t);
// True for 5..8: the displayed width is the stored height.
inline bool ExifSwapsSides(int32_t o) { return o >= 5 && o <= 8; }

}  // namespace lb
