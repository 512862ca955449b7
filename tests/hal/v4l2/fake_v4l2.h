// A scripted V4L2 capture node behind the V4l2Io seam: enough of the driver side of
// QUERYCAP / ENUM_FMT / ENUM_FRAMESIZES / G_FMT / S_FMT / REQBUFS / QUERYBUF / QBUF / DQBUF /
// STREAMON / STREAMOFF to exercise the sensor's negotiation, streaming and fault paths without
// hardware. Each delivered uncompressed frame is filled with a pattern that names the frame, row
// and column; an MJPEG or JPEG frame carries one of the scripted `jpeg_frames`. Streaming
// allocates nothing (buffers are made at REQBUFS), so allocation tests can run through it.
#pragma once

#include <linux/videodev2.h>

#include <cstdint>
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
  // Formats listed here come in these sizes only (ENUM_FRAMESIZES lists them, S_FMT picks the
  // nearest); the others in any even size up to the native one.
  struct FrameSize {
    uint32_t fourcc, width, height;
  };
  std::vector<FrameSize> sizes;
  // MJPEG and JPEG: frame k of a stream carries jpeg_frames[k % size()] (bytesused 0 for an
  // empty one, cut to the buffer for one longer than it).
  std::vector<std::vector<uint8_t>> jpeg_frames;
  uint32_t line_padding = 16;  // bytes beyond the pixels in every row
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
  uint32_t Fill(uint32_t index, uint32_t frame);  // returns bytesused
  size_t ImageBytes() const;
  bool Compressed() const;
  void PickSize(v4l2_pix_format* p) const;

  v4l2_pix_format pix_ = {};
  std::vector<std::vector<uint8_t>> buffers_;
  std::vector<uint32_t> queued_;  // reserved at REQBUFS
  int delivered_ = 0;             // frames of the current stream
  uint32_t sequence_ = 0;
};

}  // namespace lb
