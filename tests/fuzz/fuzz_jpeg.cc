// libFuzzer target: any bytes through the JPEG reader (forced, so no mutation is lost to format
// detection), then as a burst frame file the way the file sensor opens one through the codecs
// (CodecImageDecoder: ProbeImageFile, then libexif through ExifFocalPx and ExifOrientation). The
// EXIF readers take a path, so the input is also written to an in-memory file (memfd) opened by
// its /proc name; the orientation read from memory (as `refocus rerender` does) must agree.
#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "firmware/codecs/exif.h"
#include "tests/fuzz/decode_check.h"

namespace {

// The input as a file: "/proc/self/fd/N" of a memfd rewritten for every input.
const char* InputFile(const uint8_t* data, size_t size) {
  static int fd = -1;
  static char path[64];
  if (fd < 0) {
    fd = memfd_create("fuzz_jpeg", MFD_CLOEXEC);
    if (fd < 0) {
      perror("fuzz_jpeg: memfd_create");
      abort();
    }
    snprintf(path, sizeof(path), "/proc/self/fd/%d", fd);
  }
  size_t done = 0;
  while (done < size) {
    const ssize_t n = pwrite(fd, data + done, size - done, static_cast<off_t>(done));
    if (n <= 0) {
      perror("fuzz_jpeg: pwrite");
      abort();
    }
    done += static_cast<size_t>(n);
  }
  if (ftruncate(fd, static_cast<off_t>(size)) != 0) {
    perror("fuzz_jpeg: ftruncate");
    abort();
  }
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lb::fuzz::CheckDecode(data, size, lb::ImageFileType::kJpeg, "fuzz.jpeg");

  const char* path = InputFile(data, size);
  lb::ImageFileInfo memory_info, file_info;
  const lb::Status memory =
      lb::ProbeImageMemory(data, size, "fuzz.jpeg", &memory_info, lb::ImageFileType::kJpeg);
  const lb::Status file = lb::ProbeImageFile(path, &file_info);
  // The file sensor detects the format; JPEG magic must give the same header as the forced read.
  if (size >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF) {
    LB_FUZZ_REQUIRE(memory.code() == file.code(), "probe from memory '%s', from the file '%s'",
                    memory.message(), file.message());
    LB_FUZZ_REQUIRE(!file.ok() || (file_info.width == memory_info.width &&
                                   file_info.height == memory_info.height &&
                                   file_info.format == memory_info.format),
                    "file probe %dx%d, memory probe %dx%d", file_info.width, file_info.height,
                    memory_info.width, memory_info.height);
  }
  // The EXIF the file sensor reads from the first frame, for any bytes (libexif looks for the
  // APP1 segment itself); with the probed size when there is one.
  const int32_t width = memory.ok() ? memory_info.width : 4000;
  const int32_t height = memory.ok() ? memory_info.height : 3000;
  const double focal_px = lb::ExifFocalPx(path, width, height);
  LB_FUZZ_REQUIRE(std::isfinite(focal_px) && focal_px >= 0, "focal %g px", focal_px);
  const int32_t orientation = lb::ExifOrientation(path);
  LB_FUZZ_REQUIRE(orientation >= 0 && orientation <= 8, "orientation %d", orientation);
  const int32_t in_memory = lb::ExifOrientation(data, size);
  LB_FUZZ_REQUIRE(in_memory == orientation, "orientation %d from memory, %d from the file",
                  in_memory, orientation);
  return 0;
}
