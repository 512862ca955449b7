// libFuzzer target: any bytes through the JPEG reader (forced, so no mutation is lost to format
// detection).
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/decode_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lb::fuzz::CheckDecode(data, size, lb::ImageFileType::kJpeg, "fuzz.jpeg");
  return 0;
}
