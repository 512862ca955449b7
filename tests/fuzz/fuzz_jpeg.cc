// libFuzzer target: any bytes through the JPEG reader (forced, so no mutation is lost to format
// detection), then as a burst frame file the way the file sensor opens one through the codecs
// (CodecImageDecoder: ProbeImageFile, then libexif through ExifFocalPx and ExifOrientation). The
// EXIF readers take a path, so the input is also written to an in-memory file (memfd) opened by
// its /proc name; the orientation read from memory (as `refocus rerender` does) must agree. And
// the web page's thumbnail read from that descriptor, the JPEG shrunk in the decoder to a width
// taken from the input: the frame it delivers lies between that width and the probed one, and
// the orientation read from the descriptor agrees with the others.
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "firmware/codecs/exif.h"
#include "tests/fuzz/decode_check.h"

namespace {

int g_fd = -1;

// The input as a file: "/proc/self/fd/N" of a memfd (g_fd) rewritten for every input.
const char* InputFile(const uint8_t* data, size_t size) {
  int& fd = g_fd;
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
  if (lseek(fd, 0, SEEK_SET) != 0) {
    perror("fuzz_jpeg: lseek");
    abort();
  }
  return path;
}

// Counts what a read delivers and checks its order.
class CountingSink final : public lb::FrameSink {
 public:
  lb::Status BeginFrame(const lb::FrameInfo& info) override {
    info_ = info;
    ++frames_;
    return lb::Status::Ok();
  }
  lb::Status Rows(const lb::FrameRows& rows) override {
    LB_FUZZ_REQUIRE(rows.y0 == rows_ && rows.height > 0, "rows %d+%d after %d", rows.y0,
                    rows.height, rows_);
    rows_ += rows.height;
    return lb::Status::Ok();
  }
  lb::Status EndFrame() override {
    ended_ = true;
    return lb::Status::Ok();
  }
  lb::FrameInfo info_;
  int32_t frames_ = 0, rows_ = 0;
  bool ended_ = false;
};

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
  const int32_t at = lb::ExifOrientationAt(g_fd);  // the thumbnails' read
  LB_FUZZ_REQUIRE(at == orientation, "orientation %d from the descriptor, %d from the file", at,
                  orientation);
  if (memory.ok() && int64_t{memory_info.width} * memory_info.height <= lb::fuzz::kMaxFuzzPixels) {
    const int32_t min_width = 1 + static_cast<int32_t>(size % 97);
    CountingSink sink;
    const lb::Status thumb = lb::StreamImageDescriptor(g_fd, "fuzz.jpeg", min_width, sink);
    LB_FUZZ_REQUIRE(thumb.code() != lb::Code::kInternal, "%s", thumb.message());
    if (thumb.ok()) {
      const int32_t w = sink.info_.width, want = std::min(min_width, memory_info.width);
      LB_FUZZ_REQUIRE(sink.frames_ == 1 && sink.ended_ && sink.rows_ == sink.info_.height,
                      "%d frames, %d of %d rows", sink.frames_, sink.rows_, sink.info_.height);
      LB_FUZZ_REQUIRE(w >= want && w <= memory_info.width && sink.info_.height >= 1 &&
                          sink.info_.height <= memory_info.height,
                      "%dx%d for at least %d of %dx%d", w, sink.info_.height, min_width,
                      memory_info.width, memory_info.height);
    }
  }
  return 0;
}
