// Image files on the host: binary PPM/PGM (8 and 16 bit, comments), PNG (libpng) and JPEG
// (libjpeg-turbo). Every reader checks every byte it uses; a bad file gives a Status whose
// message names the file and the problem, never a crash.
#pragma once

#include <cstdint>
#include <vector>

#include "algo/core/frame.h"
#include "algo/core/status.h"

namespace lb {

struct ImageFileInfo {
  PixelFormat format = PixelFormat::kRgb8;  // kGray8, kRgb8, kGray16 or kRgb16
  int32_t width = 0;
  int32_t height = 0;
};

// Reads only the header: format and size.
Status ProbeImageFile(const char* path, ImageFileInfo* info);

// Streams the image's rows into `sink` as burst frame `index` (BeginFrame, Rows..., EndFrame),
// holding at most a strip of rows in memory. 16-bit samples are delivered native-endian.
Status StreamImageFile(const char* path, int32_t index, FrameSink& sink);

// Reads the whole image into `pixels` (tightly packed rows, native-endian samples). A host-side
// convenience for tests, tools and the Middlebury loaders; allocates.
Status ReadImageFile(const char* path, ImageFileInfo* info, std::vector<uint8_t>* pixels);

// The same readers over bytes in memory (the fuzz targets and the JPEG/XMP reader use them).
// `name` is used in error messages.
Status ReadImageMemory(const uint8_t* data, size_t size, const char* name, ImageFileInfo* info,
                       std::vector<uint8_t>* pixels);

}  // namespace lb
