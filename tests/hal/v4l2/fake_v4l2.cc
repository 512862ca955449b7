#include "tests/hal/v4l2/fake_v4l2.h"

#include <errno.h>
#include <poll.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace lb {

int FakeV4l2::Open(const char*, int) {
  if (!exists) return -ENOENT;
  ++open_fds;
  pix_ = {};
  pix_.width = width;
  pix_.height = height;
  pix_.pixelformat = formats.empty() ? 0 : formats[0];
  pix_.field = V4L2_FIELD_NONE;
  return kFd;
}

int FakeV4l2::Close(int fd) {
  if (fd != kFd) return -EBADF;
  --open_fds;
  streaming = false;
  buffers_.clear();
  queued_.clear();
  return 0;
}

bool FakeV4l2::Compressed() const {
  return pix_.pixelformat == V4L2_PIX_FMT_MJPEG || pix_.pixelformat == V4L2_PIX_FMT_JPEG;
}

void FakeV4l2::PickSize(v4l2_pix_format* p) const {
  const FrameSize* best = nullptr;
  int64_t best_distance = 0;
  for (const FrameSize& s : sizes) {
    if (s.fourcc != p->pixelformat) continue;
    const int64_t d =
        std::abs(int64_t{s.width} - p->width) + std::abs(int64_t{s.height} - p->height);
    if (best == nullptr || d < best_distance) {
      best = &s;
      best_distance = d;
    }
  }
  if (best != nullptr) {
    p->width = best->width;
    p->height = best->height;
    return;
  }
  p->width = std::min(std::max(p->width, 2u), width) & ~1u;
  p->height = std::min(std::max(p->height, 2u), height) & ~1u;
}

size_t FakeV4l2::ImageBytes() const {
  // A UVC driver's usual bound for a compressed frame.
  if (Compressed()) return static_cast<size_t>(pix_.width) * pix_.height * 2;
  size_t plane0 = static_cast<size_t>(pix_.bytesperline) * pix_.height;
  return pix_.pixelformat == V4L2_PIX_FMT_NV12 ? plane0 + plane0 / 2 : plane0;
}

int FakeV4l2::Ioctl(int fd, unsigned long request, void* arg) {
  if (fd != kFd) return -EBADF;
  if (request == fail_request) return -fail_errno;
  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto* cap = static_cast<v4l2_capability*>(arg);
      snprintf(reinterpret_cast<char*>(cap->card), sizeof(cap->card), "fake");
      cap->capabilities = caps | V4L2_CAP_DEVICE_CAPS;
      cap->device_caps = caps;
      return 0;
    }
    case VIDIOC_ENUM_FMT: {
      auto* desc = static_cast<v4l2_fmtdesc*>(arg);
      if (desc->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || desc->index >= formats.size())
        return -EINVAL;
      desc->pixelformat = formats[desc->index];
      return 0;
    }
    case VIDIOC_ENUM_FRAMESIZES: {
      auto* size = static_cast<v4l2_frmsizeenum*>(arg);
      uint32_t n = 0;
      for (const FrameSize& s : sizes) {
        if (s.fourcc != size->pixel_format) continue;
        if (n++ == size->index) {
          size->type = V4L2_FRMSIZE_TYPE_DISCRETE;
          size->discrete = {s.width, s.height};
          return 0;
        }
      }
      if (n > 0 || size->index > 0) return -EINVAL;
      if (std::find(formats.begin(), formats.end(), size->pixel_format) == formats.end())
        return -EINVAL;
      size->type = V4L2_FRMSIZE_TYPE_STEPWISE;
      size->stepwise = {2, width, 2, 2, height, 2};
      return 0;
    }
    case VIDIOC_G_FMT:
      static_cast<v4l2_format*>(arg)->fmt.pix = pix_;
      return 0;
    case VIDIOC_S_FMT: {
      if (!buffers_.empty()) return -EBUSY;
      v4l2_pix_format& p = static_cast<v4l2_format*>(arg)->fmt.pix;
      if (std::find(formats.begin(), formats.end(), p.pixelformat) == formats.end()) {
        p.pixelformat = formats[0];
      }
      PickSize(&p);
      uint32_t bpp = p.pixelformat == V4L2_PIX_FMT_YUYV   ? 2
                     : p.pixelformat == V4L2_PIX_FMT_NV12 ? 1
                                                          : 3;
      p.field = V4L2_FIELD_NONE;
      pix_ = p;
      p.bytesperline = Compressed() ? 0 : p.width * bpp + line_padding;
      pix_ = p;
      p.sizeimage = static_cast<uint32_t>(ImageBytes());
      pix_ = p;
      return 0;
    }
    case VIDIOC_REQBUFS: {
      auto* req = static_cast<v4l2_requestbuffers*>(arg);
      if (streaming || mapped > 0) return -EBUSY;
      granted_buffers = std::min(req->count, max_buffers);
      req->count = granted_buffers;
      buffers_.assign(granted_buffers, std::vector<uint8_t>(ImageBytes() + 64));
      queued_.clear();
      queued_.reserve(granted_buffers);
      return 0;
    }
    case VIDIOC_QUERYBUF: {
      auto* buf = static_cast<v4l2_buffer*>(arg);
      if (buf->index >= buffers_.size()) return -EINVAL;
      buf->length = static_cast<uint32_t>(buffers_[buf->index].size());
      buf->m.offset = buf->index * kCookieStep;
      return 0;
    }
    case VIDIOC_QBUF: {
      auto* buf = static_cast<v4l2_buffer*>(arg);
      if (buf->index >= buffers_.size()) return -EINVAL;
      if (std::find(queued_.begin(), queued_.end(), buf->index) != queued_.end()) return -EINVAL;
      queued_.push_back(buf->index);
      return 0;
    }
    case VIDIOC_DQBUF: {
      auto* buf = static_cast<v4l2_buffer*>(arg);
      if (!streaming) return -EINVAL;
      if (queued_.empty() || delivered_ == stall_after) return -EAGAIN;
      if (delivered_ == skip_at) sequence_ += skip_count;
      buf->index = queued_.front();
      queued_.erase(queued_.begin());
      buf->bytesused = Fill(buf->index, static_cast<uint32_t>(delivered_));
      buf->sequence = sequence_++;
      buf->flags = delivered_ == error_flag_at ? V4L2_BUF_FLAG_ERROR : 0;
      buf->timestamp.tv_sec = 100 + delivered_;
      buf->timestamp.tv_usec = 0;
      ++delivered_;
      return 0;
    }
    case VIDIOC_G_PARM: {
      auto* parm = static_cast<v4l2_streamparm*>(arg);
      parm->parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
      parm->parm.capture.timeperframe = {1, fps};
      return 0;
    }
    case VIDIOC_S_PARM: {
      auto* parm = static_cast<v4l2_streamparm*>(arg);
      const v4l2_fract& t = parm->parm.capture.timeperframe;
      if (t.numerator == 0) return -EINVAL;
      fps = t.denominator / t.numerator;
      return 0;
    }
    case VIDIOC_STREAMON:
      if (streaming) return -EBUSY;
      ++streamon_calls;
      streaming = true;
      delivered_ = 0;
      return 0;
    case VIDIOC_STREAMOFF:
      ++streamoff_calls;
      streaming = false;
      queued_.clear();
      return 0;
    default:
      return -ENOTTY;
  }
}

int FakeV4l2::Poll(int fd, short, int, short* revents) {
  if (fd != kFd) return -EBADF;
  if (!streaming) {
    *revents = POLLERR;
    return 1;
  }
  if (queued_.empty() || delivered_ == stall_after) return 0;  // as if the timeout ran out
  *revents = POLLIN;
  return 1;
}

int FakeV4l2::Map(int fd, size_t length, uint32_t offset, void** addr) {
  uint32_t index = offset / kCookieStep;
  if (fd != kFd || index >= buffers_.size() || length != buffers_[index].size()) return -EINVAL;
  *addr = buffers_[index].data();
  ++mapped;
  return 0;
}

int FakeV4l2::Unmap(void*, size_t) {
  --mapped;
  return 0;
}

uint32_t FakeV4l2::Fill(uint32_t index, uint32_t frame) {
  uint8_t* base = buffers_[index].data();
  std::memset(base, 0xEE, buffers_[index].size());
  if (Compressed()) {
    if (jpeg_frames.empty()) return 0;
    const std::vector<uint8_t>& jpeg = jpeg_frames[frame % jpeg_frames.size()];
    const size_t n = std::min(jpeg.size(), buffers_[index].size());
    if (n > 0) std::memcpy(base, jpeg.data(), n);
    return static_cast<uint32_t>(n);
  }
  uint32_t bpp = pix_.pixelformat == V4L2_PIX_FMT_YUYV   ? 2
                 : pix_.pixelformat == V4L2_PIX_FMT_NV12 ? 1
                                                         : 3;
  for (uint32_t y = 0; y < pix_.height; ++y) {
    for (uint32_t x = 0; x < pix_.width * bpp; ++x) {
      base[y * pix_.bytesperline + x] = Pattern(frame, 0, y, x);
    }
  }
  if (pix_.pixelformat == V4L2_PIX_FMT_NV12) {
    uint8_t* uv = base + static_cast<size_t>(pix_.bytesperline) * pix_.height;
    for (uint32_t y = 0; y < pix_.height / 2; ++y) {
      for (uint32_t x = 0; x < pix_.width; ++x)
        uv[y * pix_.bytesperline + x] = Pattern(frame, 1, y, x);
    }
  }
  return static_cast<uint32_t>(ImageBytes());
}

}  // namespace lb
