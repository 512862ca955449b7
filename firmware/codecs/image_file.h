// The product's image readers, one per format, behind one door that tells them apart by their
// magic bytes: binary PPM/PGM (8 and 16 bit, comments; pnm_reader.cc), PNG (libpng;
// png_reader.cc) and JPEG (libjpeg-turbo; jpeg_reader.cc), from a file or from memory. Every
// reader checks every byte it uses; a bad file gives a Status whose message names the file and
// the problem, never a crash.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "algo/core/frame.h"
#include "algo/core/status.h"

namespace lb {

// How to decode bytes: by their magic bytes (kAuto) or as one format whatever they start with
// (the fuzz targets force a format so every mutation reaches that decoder).
enum class ImageFileType : uint8_t { kAuto, kPnm, kPng, kJpeg };

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

// StreamImageFile from an open descriptor (borrowed: read from where it stands, not closed) as
// frame 0, `name` in error messages. A JPEG is decoded at libjpeg's smallest scale M/8 that keeps
// it at least `min_width` wide (0: whole; FrameInfo gives the size delivered): the web page's
// thumbnails. Other formats come whole.
Status StreamImageDescriptor(int fd, const char* name, int32_t min_width, FrameSink& sink);

// Reads the whole image into `pixels` (tightly packed rows, native-endian samples). A host-side
// convenience for tests, tools and the Middlebury loaders; allocates.
Status ReadImageFile(const char* path, ImageFileInfo* info, std::vector<uint8_t>* pixels);

// The same readers over bytes in memory (the fuzz targets and `refocus rerender` use them).
// `name` is used in error messages. On error `pixels` is left empty.
Status ReadImageMemory(const uint8_t* data, size_t size, const char* name, ImageFileInfo* info,
                       std::vector<uint8_t>* pixels, ImageFileType type = ImageFileType::kAuto);
Status ProbeImageMemory(const uint8_t* data, size_t size, const char* name, ImageFileInfo* info,
                        ImageFileType type = ImageFileType::kAuto);

// Memory a caller sized once, for a read that must not allocate (the web page's engine): the
// reader decodes each strip into `strip` instead of a heap buffer, and an image wider or taller
// than the caller takes is kOutOfMemory before any pixel is decoded.
struct ImageReadMemory {
  uint8_t* strip = nullptr;  // at least ImageStripBytes(max_width, the widest format expected)
  size_t strip_bytes = 0;
  int32_t max_width = 0;
  int32_t max_height = 0;
};

// StreamImageFile over bytes in memory, with the caller's strip (the codec libraries' own state
// aside, nothing is allocated). Interlaced PNGs need the whole image at once: kOutOfMemory unless
// the strip holds it.
Status StreamImageMemory(const uint8_t* data, size_t size, const char* name, int32_t index,
                         FrameSink& sink, const ImageReadMemory& memory,
                         ImageFileType type = ImageFileType::kAuto);

// Frames are capped at this size in each direction (a corrupt header cannot ask for gigabytes).
inline constexpr int32_t kMaxImageSide = 16384;
// Streaming readers deliver strips of at most this many rows.
inline constexpr int32_t kImageStripRows = 16;

// The strip a reader decodes into for an image `width` pixels wide of `format`.
inline size_t ImageStripBytes(int32_t width, PixelFormat format) {
  return static_cast<size_t>(width) * static_cast<size_t>(BytesPerPixel(format)) * kImageStripRows;
}

}  // namespace lb
