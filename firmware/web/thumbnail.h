// Gallery thumbnails straight from a photo's own main image, through the product's one image
// reader and one JPEG writer (firmware/codecs): the reader has libjpeg-turbo decode it already
// shrunk in the DCT domain (scale M/8, the smallest that still gives at least the wanted width,
// so a 12 MP photo costs a 1/8 decode), an area average takes it the rest of the way, and the
// writer encodes the result. A strip of rows of each is held, so the memory is a few tens of
// bytes a column.
// The embedded depth and all-in-focus images of a refocusable JPEG are APP segments the decoder
// skips. The photo's EXIF Orientation is written into the thumbnail (not applied to its
// pixels), so a browser turns both the same way.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "algo/core/status.h"

namespace lb {

// Reads the JPEG from `fd` (borrowed; read from its current offset) and writes a JPEG at most
// `width` px wide (narrower images keep their width) into `out`. The reader's errors as they are:
// kCorruptData for bytes that do not decode, kUnsupported for an image over 16384 px a side.
// `between_strips`, when given, is called before each strip of decoded rows (so the work can
// pause for the camera); its error ends the thumbnail with that error.
Status MakeThumbnail(int fd, int32_t width, int quality, std::vector<uint8_t>* out,
                     const std::function<Status()>& between_strips = {});

}  // namespace lb
