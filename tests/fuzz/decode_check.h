// What every reader fuzz target checks beyond "no crash, no sanitizer report": a failure leaves
// no pixels and names the input; a success delivers exactly the probed size and format.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "firmware/codecs/image_file.h"

namespace lb::fuzz {

// Huge (valid) images only make the fuzzer slow: the readers' 16384 cap is tested elsewhere.
inline constexpr int64_t kMaxFuzzPixels = int64_t{1} << 18;

#define LB_FUZZ_REQUIRE(cond, ...)                                  \
  do {                                                              \
    if (!(cond)) {                                                  \
      fprintf(stderr, "broken invariant: " #cond ": " __VA_ARGS__); \
      fprintf(stderr, "\n");                                        \
      abort();                                                      \
    }                                                               \
  } while (0)

inline void CheckDecode(const uint8_t* data, size_t size, ImageFileType type, const char* name) {
  ImageFileInfo probed;
  const Status probe = ProbeImageMemory(data, size, name, &probed, type);
  if (probe.ok()) {
    LB_FUZZ_REQUIRE(probed.width > 0 && probed.width <= kMaxImageSide, "width %d", probed.width);
    LB_FUZZ_REQUIRE(probed.height > 0 && probed.height <= kMaxImageSide, "height %d",
                    probed.height);
    if (int64_t{probed.width} * probed.height > kMaxFuzzPixels) return;
  }
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  const Status read = ReadImageMemory(data, size, name, &info, &pixels, type);
  LB_FUZZ_REQUIRE(strncmp(read.message(), name, strlen(name)) == 0 || read.ok(), "message '%s'",
                  read.message());
  // kInternal means a reader broke its own contract (rows out of order, a size it did not
  // expect): a bug even though nothing crashed.
  LB_FUZZ_REQUIRE(read.code() != Code::kInternal && probe.code() != Code::kInternal, "%s",
                  read.code() == Code::kInternal ? read.message() : probe.message());
  if (!read.ok()) {
    LB_FUZZ_REQUIRE(pixels.empty(), "%zu pixel bytes after '%s'", pixels.size(), read.message());
    return;
  }
  // The full read parses the same header the probe did.
  LB_FUZZ_REQUIRE(probe.ok(), "read succeeded but probe failed: %s", probe.message());
  LB_FUZZ_REQUIRE(
      info.width == probed.width && info.height == probed.height && info.format == probed.format,
      "read %dx%d %s, probed %dx%d %s", info.width, info.height, PixelFormatName(info.format),
      probed.width, probed.height, PixelFormatName(probed.format));
  const size_t expect = static_cast<size_t>(info.width) * static_cast<size_t>(info.height) *
                        static_cast<size_t>(BytesPerPixel(info.format));
  LB_FUZZ_REQUIRE(pixels.size() == expect, "%zu pixel bytes, expected %zu", pixels.size(), expect);
}

}  // namespace lb::fuzz
