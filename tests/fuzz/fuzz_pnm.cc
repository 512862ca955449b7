// libFuzzer target: any bytes through the binary PPM/PGM reader (forced, so no mutation is lost to
// format detection).
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/decode_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lb::fuzz::CheckDecode(data, size, lb::ImageFileType::kPnm, "fuzz.pnm");
  return 0;
}
