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
      wanted_fps_(options.fps),
      max_corrupt_(options.max_corrupt_frames),
      log_(options.log),
      log_context_(options.log_context) {
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
  if (max_corrupt_ < 0 || max_corrupt_ > kMaxFrames) {
    return Status(Code::kInvalidArgument, "%s: %d corrupt frames allowed, 0..%d", device_,
                  max_corrupt_, kMaxFrames);
  }
  config_ = config;
  Status status = OpenAndNegotiate(config);
  if (status.ok()) status = SetFrameRate();
  if (status.ok()) status = MapBuffers();
  if (status.ok() && layout_.compressed) {
    status = decoder_.Configure(layout_.width, layout_.height);
    if (!status.ok()) status.Prefix("%s: ", device_);
  } else if (status.ok()) {
    decoder_.Release();
  }
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

  v4l2_format fmt;
  memset(&fmt, 0, sizeof(fmt));
  fmt.type = kCapture;
  if (int r = io_->Ioctl(fd_, VIDIOC_G_FMT, &fmt); r < 0) return IoctlError("VIDIOC_G_FMT", -r);
  if (config.width > 0) fmt.fmt.pix.width = static_cast<uint32_t>(config.width);
  if (config.height > 0) fmt.fmt.pix.height = static_cast<uint32_t>(config.height);

  uint32_t listed[64];
  bool at_size[64];
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
    at_size[count] = OffersSize(desc.pixelformat, fmt.fmt.pix.width, fmt.fmt.pix.height);
  }
  LB_RETURN_IF_ERROR(ChooseFourcc(device_, listed, at_size, count, wanted_fourcc_, &fourcc_));

  fmt.fmt.pix.pixelformat = fourcc_;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  fmt.fmt.pix.bytesperline = 0;  // let the driver pick its natural stride
  fmt.fmt.pix.sizeimage = 0;
  if (int r = io_->Ioctl(fd_, VIDIOC_S_FMT, &fmt); r < 0) return IoctlError("VIDIOC_S_FMT", -r);
  return LayoutFromFormat(device_, fmt.fmt.pix, fourcc_, &layout_);
}

bool V4l2Sensor::OffersSize(uint32_t fourcc, uint32_t width, uint32_t height) {
  // A UVC camera lists a few dozen sizes at most.
  for (uint32_t index = 0; index < 256; ++index) {
    v4l2_frmsizeenum size;
    memset(&size, 0, sizeof(size));
    size.index = index;
    size.pixel_format = fourcc;
    if (io_->Ioctl(fd_, VIDIOC_ENUM_FRAMESIZES, &size) < 0) return index == 0;
    if (size.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
      if (size.discrete.width == width && size.discrete.height == height) return true;
      continue;
    }
    // Stepwise or continuous: one range, the only entry.
    const v4l2_frmsize_stepwise& r = size.stepwise;
    auto within = [](uint32_t v, uint32_t lo, uint32_t hi, uint32_t step) {
      return v >= lo && v <= hi && (step == 0 || (v - lo) % step == 0);
    };
    return within(width, r.min_width, r.max_width, r.step_width) &&
           within(height, r.min_height, r.max_height, r.step_height);
  }
  return false;
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
  corrupt_frames_ = 0;
  int32_t with_driver = buffer_count_;
  for (int32_t i = 0; i < config_.frames;) {
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
    --with_driver;
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
    if (layout_.compressed) {
      bool delivered = false;
      LB_RETURN_IF_ERROR(DeliverMjpeg(sink, buf, i, &delivered));
      if (delivered) ++i;
    } else {
      if (buf.bytesused != 0 && buf.bytesused < layout_.min_bytes) {
        return Status(Code::kCorruptData, "%s: frame %d holds %u bytes, %zu expected", device_, i,
                      buf.bytesused, layout_.min_bytes);
      }
      LB_RETURN_IF_ERROR(Deliver(sink, buf, i));
      ++i;
    }
    // Requeue only buffers still needed, so the tail of the burst does not wait on the driver.
    if (with_driver < config_.frames - i) {
      LB_RETURN_IF_ERROR(QueueBuffer(buf.index));
      ++with_driver;
    }
  }
  return Status::Ok();
}

FrameInfo V4l2Sensor::Info(const v4l2_buffer& buf, int32_t index) const {
  FrameInfo info;
  info.index = index;
  info.format = layout_.format;
  info.width = layout_.width;
  info.height = layout_.height;
  info.timestamp_ns = static_cast<int64_t>(buf.timestamp.tv_sec) * 1000000000 +
                      static_cast<int64_t>(buf.timestamp.tv_usec) * 1000;
  info.sequence = buf.sequence;
  return info;
}

Status V4l2Sensor::Deliver(FrameSink& sink, const v4l2_buffer& buf, int32_t index) {
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
  Status status = sink.BeginFrame(Info(buf, index));
  if (status.ok()) status = sink.Rows(rows);
  if (status.ok()) status = sink.EndFrame();
  if (!status.ok()) status.Prefix("%s: frame %d: ", device_, index);
  return status;
}

Status V4l2Sensor::DeliverMjpeg(FrameSink& sink, const v4l2_buffer& buf, int32_t index,
                                bool* delivered) {
  const Buffer& b = buffers_[buf.index];
  bool began = false;
  Status status;
  if (buf.bytesused > b.length) {
    status =
        Status(Code::kCorruptData, "%u bytes used in a buffer of %zu", buf.bytesused, b.length);
  } else {
    status = decoder_.Decode(static_cast<const uint8_t*>(b.addr), buf.bytesused, Info(buf, index),
                             sink, &began);
  }
  *delivered = status.ok();
  if (status.ok()) return status;
  if (began) return status.Prefix("%s: frame %d (sequence %u): ", device_, index, buf.sequence);
  ++corrupt_frames_;
  if (corrupt_frames_ > max_corrupt_) {
    return status.Prefix(
        "%s: %d corrupt MJPEG frames in this burst, at most %d skipped; burst abandoned; the "
        "last (sequence %u): ",
        device_, corrupt_frames_, max_corrupt_, buf.sequence);
  }
  if (log_ != nullptr) {
    char line[Status::kMaxMessage + 96];
    snprintf(line, sizeof(line),
             "%s: corrupt MJPEG frame (sequence %u) skipped, %d of at most %d this burst: %s",
             device_, buf.sequence, corrupt_frames_, max_corrupt_, status.message());
    log_(log_context_, line);
  }
  return Status::Ok();
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
