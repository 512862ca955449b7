// A scripted V4L2 capture node behind the V4l2Io seam: enough of the driver side of
// QUERYCAP / ENUM_FMT / G_FMT / S_FMT / REQBUFS / QUERYBUF / QBUF / DQBUF / STREAMON / STREAMOFF
// to exercise the sensor's negotiation, streaming and fault paths without hardware. Each
// delivered frame is filled with a pattern that names the frame, row and column.
#pragma once

#include <linux/videodev2.h>

#include <cstdint>
#include <deque>
#include <vector>

#include "hal/v4l2/v4l2_io.h"

namespace lb {

class FakeV4l2 : public V4l2Io {
 public:
  // The script.
  bool exists = true;
  uint32_t caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  std::vector<uint32_t> formats = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_NV12, V4L2_PIX_FMT_RGB24};
  uint32_t width = 64, height = 48;  // the native size; S_FMT grants any even size up to it
  uint32_t line_padding = 16;        // bytes beyond the pixels in every row
  uint32_t max_buffers = 8;
  int stall_after = -1;  // frames delivered per stream before it goes quiet (-1 never)
  int skip_at = -1;      // frame of the stream before which the driver skips `skip_count`
  uint32_t skip_count = 0;
  int error_flag_at = -1;  // frame of the stream whose buffer is flagged V4L2_BUF_FLAG_ERROR
  unsigned long fail_request = 0;  // this ioctl fails with fail_errno
  int fail_errno = 0;

  // Observations.
  int open_fds = 0;
  int mapped = 0;
  bool streaming = false;
  int streamon_calls = 0;
  int streamoff_calls = 0;
  uint32_t granted_buffers = 0;
  uint32_t fps = 30;  // what S_PARM set

  static uint8_t Pattern(uint32_t frame, uint32_t plane, uint32_t y, uint32_t x) {
    return static_cast<uint8_t>(frame * 31 + plane * 101 + y * 7 + x);
  }

  int Open(const char* path, int flags) override;
  int Close(int fd) override;
  int Ioctl(int fd, unsigned long request, void* arg) override;
  int Poll(int fd, short events, int timeout_ms, short* revents) override;
  int Map(int fd, size_t length, uint32_t offset, void** addr) override;
  int Unmap(void* addr, size_t length) override;

 private:
  static constexpr int kFd = 42;
  static constexpr uint32_t kCookieStep = 0x100000;
  void Fill(uint32_t index, uint32_t frame);
  size_t ImageBytes() const;

  v4l2_pix_format pix_ = {};
  std::vector<std::vector<uint8_t>> buffers_;
  std::deque<uint32_t> queued_;
  int delivered_ = 0;  // frames of the current stream
  uint32_t sequence_ = 0;
};

}  // namespace lb
