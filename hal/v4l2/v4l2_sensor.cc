#include "hal/v4l2/v4l2_sensor.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <time.h>

#include <cstdio>
#include <cstring>

namespace lb {
namespace {

constexpr uint32_t kCapture = V4L2_BUF_TYPE_VIDEO_CAPTURE;

int64_t MonotonicMs() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000 + ts.tv_nsec / 1000000;
}

// What a node that is no single-planar capture node is, for the message that refuses it.
const char* NodeKind(uint32_t caps) {
  if (caps & (V4L2_CAP_VIDEO_M2M | V4L2_CAP_VIDEO_M2M_MPLANE)) {
    return "a memory-to-memory device: a codec or scaler";
  }
  if (caps & (V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_VIDEO_OUTPUT_MPLANE | V4L2_CAP_VIDEO_OUTPUT_OVERLAY))
    return "a video output";
  // A UVC camera has one of these next to its capture node.
  if (caps & V4L2_CAP_META_CAPTURE) return "a metadata node: the pictures come from another node";
  if (caps & (V4L2_CAP_VBI_CAPTURE | V4L2_CAP_SLICED_VBI_CAPTURE)) return "a VBI (teletext) node";
  if (caps & V4L2_CAP_SDR_CAPTURE) return "a software-defined radio";
  if (caps & (V4L2_CAP_RADIO | V4L2_CAP_TUNER)) return "a radio tuner";
  if (caps & V4L2_CAP_TOUCH) return "a touch sensor";
  return "no video capture capability";
}

}  // namespace

V4l2Sensor::V4l2Sensor(const V4l2Options& options, V4l2Io* io)
    : io_(io ? io : &SystemV4l2Io()),
      wanted_fourcc_(options.fourcc),
      wanted_buffers_(options.buffers),
      wanted_fps_(options.fps) {
  snprintf(device_, sizeof(device_), "%s", options.device ? options.device : "");
}

V4l2Sensor::~V4l2Sensor() { Stop(); }

Status V4l2Sensor::IoctlError(const char* what, int err) const {
  char text[96];
  Code code = err == ENODEV ? Code::kNotFound : err == EBUSY ? Code::kBusy : Code::kIoError;
  return Status(code, "%s: %s failed: %s (errno %d)", device_, what,
                V4l2ErrnoText(err, text, sizeof(text)), err);
}

Status V4l2Sensor::CheckCaps(const v4l2_capability& cap) const {
  const uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  const char* card = reinterpret_cast<const char*>(cap.card);
  if (caps & V4L2_CAP_VIDEO_CAPTURE) {
    if (caps & V4L2_CAP_STREAMING) return Status::Ok();
    return Status(Code::kUnsupported,
                  "%s (%.32s): a capture node without streaming I/O (read() only); mmap "
                  "streaming is needed",
                  device_, card);
  }
  if (caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE) {
    return Status(Code::kUnsupported,
                  "%s (%.32s): a multi-planar capture node; the v4l2 backend reads single-planar "
                  "nodes only",
                  device_, card);
  }
  return Status(Code::kUnsupported, "%s (%.32s): not a capture device (%s; caps 0x%08x)", device_,
                card, NodeKind(caps), caps);
}

Status V4l2Sensor::Probe() {
  char text[96];
  const int fd = io_->Open(device_, O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd == -ENOENT || fd == -ENODEV || fd == -ENXIO) {
    // ENODEV, ENXIO: a node whose driver is gone (an unplugged camera).
    return Status(Code::kNotFound, "camera %s: no such device", device_);
  }
  if (fd == -EISDIR)
    return Status(Code::kUnsupported, "camera %s: not a V4L2 device (a folder)", device_);
  if (fd < 0) {
    return Status(Code::kIoError, "camera %s: cannot open: %s (errno %d)", device_,
                  V4l2ErrnoText(-fd, text, sizeof(text)), -fd);
  }
  v4l2_capability cap;
  memset(&cap, 0, sizeof(cap));
  const int r = io_->Ioctl(fd, VIDIOC_QUERYCAP, &cap);
  (void)io_->Close(fd);
  // ENOTTY: a file or a device of another kind; every V4L2 node answers QUERYCAP.
  if (r == -ENOTTY || r == -EINVAL) {
    return Status(Code::kUnsupported, "camera %s: not a V4L2 device", device_);
  }
  if (r < 0) return IoctlError("VIDIOC_QUERYCAP", -r).Prefix("camera ");
  Status s = CheckCaps(cap);
  if (!s.ok()) s.Prefix("camera ");
  return s;
}

Status V4l2Sensor::Configure(const SensorConfig& config, SensorMode* mode) {
  Stop();
  if (config.frames < 1 || config.frames > kMaxFrames || config.timeout_ms <= 0 ||
      config.width < 0 || config.height < 0) {
    return Status(Code::kInvalidArgument,
                  "%s: burst of %d frames, timeout %d ms, size %dx%d (frames 1..%d, timeout > 0)",
                  device_, config.frames, config.timeout_ms, config.width, config.height,
                  kMaxFrames);
  }
  if (wanted_fps_ < 0 || wanted_fps_ > 1000) {
    return Status(Code::kInvalidArgument, "%s: %d fps requested, 0..1000 allowed", device_,
                  wanted_fps_);
  }
  if (wanted_buffers_ != 0 && (wanted_buffers_ < 2 || wanted_buffers_ > V4l2Options::kMaxBuffers)) {
    return Status(Code::kInvalidArgument, "%s: %d buffers requested, 2..%d allowed", device_,
                  wanted_buffers_, V4l2Options::kMaxBuffers);
  }
  config_ = config;
  Status status = OpenAndNegotiate(config);
  if (status.ok()) status = SetFrameRate();
  if (status.ok()) status = MapBuffers();
  if (!status.ok()) {
    Stop();
    return status;
  }
  mode->width = layout_.width;
  mode->height = layout_.height;
  mode->format = layout_.format;
  mode->frames = config.frames;
  return Status::Ok();
}

Status V4l2Sensor::OpenAndNegotiate(const SensorConfig& config) {
  int fd = io_->Open(device_, O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    char text[96];
    return Status(fd == -ENOENT ? Code::kNotFound : Code::kIoError,
                  "%s: cannot open: %s (errno %d)", device_, V4l2ErrnoText(-fd, text, sizeof(text)),
                  -fd);
  }
  fd_ = fd;

  v4l2_capability cap;
  memset(&cap, 0, sizeof(cap));
  if (int r = io_->Ioctl(fd_, VIDIOC_QUERYCAP, &cap); r < 0)
    return IoctlError("VIDIOC_QUERYCAP", -r);
  LB_RETURN_IF_ERROR(CheckCaps(cap));

  uint32_t listed[64];
  size_t count = 0;
  for (; count < 64; ++count) {
    v4l2_fmtdesc desc;
    memset(&desc, 0, sizeof(desc));
    desc.index = static_cast<uint32_t>(count);
    desc.type = kCapture;
    int r = io_->Ioctl(fd_, VIDIOC_ENUM_FMT, &desc);
    if (r == -EINVAL) break;  // the end of the list
    if (r < 0) return IoctlError("VIDIOC_ENUM_FMT", -r);
    listed[count] = desc.pixelformat;
  }
  LB_RETURN_IF_ERROR(ChooseFourcc(device_, listed, count, wanted_fourcc_, &fourcc_));

  v4l2_format fmt;
  memset(&fmt, 0, sizeof(fmt));
  fmt.type = kCapture;
  if (int r = io_->Ioctl(fd_, VIDIOC_G_FMT, &fmt); r < 0) return IoctlError("VIDIOC_G_FMT", -r);
  if (config.width > 0) fmt.fmt.pix.width = static_cast<uint32_t>(config.width);
  if (config.height > 0) fmt.fmt.pix.height = static_cast<uint32_t>(config.height);
  fmt.fmt.pix.pixelformat = fourcc_;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  fmt.fmt.pix.bytesperline = 0;  // let the driver pick its natural stride
  fmt.fmt.pix.sizeimage = 0;
  if (int r = io_->Ioctl(fd_, VIDIOC_S_FMT, &fmt); r < 0) return IoctlError("VIDIOC_S_FMT", -r);
  return LayoutFromFormat(device_, fmt.fmt.pix, fourcc_, &layout_);
}

Status V4l2Sensor::SetFrameRate() {
  if (wanted_fps_ == 0) return Status::Ok();
  v4l2_streamparm parm;
  memset(&parm, 0, sizeof(parm));
  parm.type = kCapture;
  if (int r = io_->Ioctl(fd_, VIDIOC_G_PARM, &parm); r < 0) return IoctlError("VIDIOC_G_PARM", -r);
  if (!(parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
    return Status(Code::kUnsupported, "%s: the driver has no settable frame rate (%d fps asked)",
                  device_, wanted_fps_);
  }
  parm.parm.capture.timeperframe.numerator = 1;
  parm.parm.capture.timeperframe.denominator = static_cast<uint32_t>(wanted_fps_);
  if (int r = io_->Ioctl(fd_, VIDIOC_S_PARM, &parm); r < 0) return IoctlError("VIDIOC_S_PARM", -r);
  return Status::Ok();
}

Status V4l2Sensor::MapBuffers() {
  v4l2_requestbuffers req;
  memset(&req, 0, sizeof(req));
  int32_t wanted = wanted_buffers_;
  if (wanted == 0) {
    wanted = config_.frames < 2 ? 2 : config_.frames;
    if (wanted > V4l2Options::kMaxBuffers) wanted = V4l2Options::kMaxBuffers;
  }
  req.count = static_cast<uint32_t>(wanted);
  req.type = kCapture;
  req.memory = V4L2_MEMORY_MMAP;
  if (int r = io_->Ioctl(fd_, VIDIOC_REQBUFS, &req); r < 0) return IoctlError("VIDIOC_REQBUFS", -r);
  // Recorded before the checks so Stop frees whatever the driver allocated.
  buffer_count_ = static_cast<int32_t>(req.count < V4l2Options::kMaxBuffers
                                           ? req.count
                                           : static_cast<uint32_t>(V4l2Options::kMaxBuffers));
  if (req.count < 2 || req.count > static_cast<uint32_t>(V4l2Options::kMaxBuffers)) {
    return Status(Code::kUnsupported, "%s: the driver granted %u buffers, 2..%d needed", device_,
                  req.count, V4l2Options::kMaxBuffers);
  }
  for (int32_t i = 0; i < buffer_count_; ++i) {
    v4l2_buffer buf;
    memset(&buf, 0, sizeof(buf));
    buf.index = static_cast<uint32_t>(i);
    buf.type = kCapture;
    buf.memory = V4L2_MEMORY_MMAP;
    if (int r = io_->Ioctl(fd_, VIDIOC_QUERYBUF, &buf); r < 0) {
      return IoctlError("VIDIOC_QUERYBUF", -r);
    }
    if (buf.length < layout_.min_bytes) {
      return Status(Code::kCorruptData, "%s: buffer %d holds %u bytes, a frame needs %zu", device_,
                    i, buf.length, layout_.min_bytes);
    }
    void* addr = nullptr;
    if (int r = io_->Map(fd_, buf.length, buf.m.offset, &addr); r < 0) {
      return IoctlError("mmap", -r);
    }
    buffers_[i].addr = addr;
    buffers_[i].length = buf.length;
  }
  return Status::Ok();
}

Status V4l2Sensor::QueueBuffer(uint32_t index) {
  v4l2_buffer buf;
  memset(&buf, 0, sizeof(buf));
  buf.index = index;
  buf.type = kCapture;
  buf.memory = V4L2_MEMORY_MMAP;
  if (int r = io_->Ioctl(fd_, VIDIOC_QBUF, &buf); r < 0) return IoctlError("VIDIOC_QBUF", -r);
  return Status::Ok();
}

Status V4l2Sensor::WaitFrame() {
  int64_t deadline = MonotonicMs() + config_.timeout_ms;
  for (;;) {
    int64_t left = deadline - MonotonicMs();
    if (left < 0) left = 0;
    short revents = 0;
    int r = io_->Poll(fd_, POLLIN, static_cast<int>(left), &revents);
    if (r == -EINTR) continue;
    if (r < 0) return IoctlError("poll", -r);
    if (r == 0) {
      return Status(Code::kTimeout, "%s: no frame within %d ms", device_, config_.timeout_ms);
    }
    if (revents & (POLLERR | POLLHUP | POLLNVAL)) {
      return Status(Code::kIoError, "%s: poll reports an error on the device (revents 0x%x)",
                    device_, static_cast<unsigned>(revents));
    }
    if (revents & POLLIN) return Status::Ok();
  }
}

Status V4l2Sensor::CaptureBurst(FrameSink& sink) {
  if (fd_ < 0) return Status(Code::kInvalidArgument, "%s: CaptureBurst before Configure", device_);
  Status status = Stream(sink);
  if (streaming_) {
    // STREAMOFF also takes every buffer back from the driver, ready for the next burst.
    int type = kCapture;
    int r = io_->Ioctl(fd_, VIDIOC_STREAMOFF, &type);
    streaming_ = false;
    if (r < 0 && status.ok()) status = IoctlError("VIDIOC_STREAMOFF", -r);
  }
  return status;
}

Status V4l2Sensor::Stream(FrameSink& sink) {
  for (int32_t i = 0; i < buffer_count_; ++i) {
    LB_RETURN_IF_ERROR(QueueBuffer(static_cast<uint32_t>(i)));
  }
  int type = kCapture;
  if (int r = io_->Ioctl(fd_, VIDIOC_STREAMON, &type); r < 0) {
    // Buffers queued before a failed STREAMON stay with the driver until STREAMOFF.
    streaming_ = true;
    return IoctlError("VIDIOC_STREAMON", -r);
  }
  streaming_ = true;
  sequence_.Reset();
  for (int32_t i = 0; i < config_.frames; ++i) {
    v4l2_buffer buf;
    for (;;) {
      LB_RETURN_IF_ERROR(WaitFrame());
      memset(&buf, 0, sizeof(buf));
      buf.type = kCapture;
      buf.memory = V4L2_MEMORY_MMAP;
      int r = io_->Ioctl(fd_, VIDIOC_DQBUF, &buf);
      if (r == -EAGAIN) continue;  // woken without a finished buffer
      if (r < 0) return IoctlError("VIDIOC_DQBUF", -r);
      break;
    }
    if (buf.index >= static_cast<uint32_t>(buffer_count_)) {
      return Status(Code::kInternal, "%s: the driver returned buffer %u of %d", device_, buf.index,
                    buffer_count_);
    }
    uint32_t missing = 0;
    if (!sequence_.Next(buf.sequence, &missing)) {
      return Status(Code::kCorruptData, "%s: frame %d: sequence %u does not follow %u", device_, i,
                    buf.sequence, sequence_.last());
    }
    if (missing > 0) {
      return Status(Code::kCorruptData,
                    "%s: frame %d: %u frame(s) dropped before sequence %u; burst abandoned",
                    device_, i, missing, buf.sequence);
    }
    if (buf.flags & V4L2_BUF_FLAG_ERROR) {
      return Status(Code::kCorruptData,
                    "%s: frame %d (sequence %u) flagged bad by the driver; burst abandoned",
                    device_, i, buf.sequence);
    }
    if (buf.bytesused != 0 && buf.bytesused < layout_.min_bytes) {
      return Status(Code::kCorruptData, "%s: frame %d holds %u bytes, %zu expected", device_, i,
                    buf.bytesused, layout_.min_bytes);
    }
    LB_RETURN_IF_ERROR(Deliver(sink, buf, i));
    // Requeue only buffers still needed, so the tail of the burst does not wait on the driver.
    if (i + buffer_count_ < config_.frames) LB_RETURN_IF_ERROR(QueueBuffer(buf.index));
  }
  return Status::Ok();
}

Status V4l2Sensor::Deliver(FrameSink& sink, const v4l2_buffer& buf, int32_t index) {
  FrameInfo info;
  info.index = index;
  info.format = layout_.format;
  info.width = layout_.width;
  info.height = layout_.height;
  info.timestamp_ns = static_cast<int64_t>(buf.timestamp.tv_sec) * 1000000000 +
                      static_cast<int64_t>(buf.timestamp.tv_usec) * 1000;
  info.sequence = buf.sequence;
  const uint8_t* base = static_cast<const uint8_t*>(buffers_[buf.index].addr);
  FrameRows rows;
  rows.y0 = 0;
  rows.height = layout_.height;
  rows.planes[0] = base;
  rows.strides[0] = layout_.stride;
  if (layout_.format == PixelFormat::kNv12) {
    rows.planes[1] = base + layout_.uv_offset;
    rows.strides[1] = layout_.stride;
  }
  Status status = sink.BeginFrame(info);
  if (status.ok()) status = sink.Rows(rows);
  if (status.ok()) status = sink.EndFrame();
  if (!status.ok()) status.Prefix("%s: frame %d: ", device_, index);
  return status;
}

void V4l2Sensor::Stop() {
  if (fd_ < 0) return;
  if (streaming_) {
    int type = kCapture;
    (void)io_->Ioctl(fd_, VIDIOC_STREAMOFF, &type);
    streaming_ = false;
  }
  for (int32_t i = 0; i < buffer_count_; ++i) {
    if (buffers_[i].addr) (void)io_->Unmap(buffers_[i].addr, buffers_[i].length);
    buffers_[i] = Buffer();
  }
  if (buffer_count_ > 0) {
    // Frees the driver's buffers; closing the node would too, this just says so.
    v4l2_requestbuffers req;
    memset(&req, 0, sizeof(req));
    req.type = kCapture;
    req.memory = V4L2_MEMORY_MMAP;
    (void)io_->Ioctl(fd_, VIDIOC_REQBUFS, &req);
  }
  buffer_count_ = 0;
  (void)io_->Close(fd_);
  fd_ = -1;
}

}  // namespace lb
