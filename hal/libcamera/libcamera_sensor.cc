#include "hal/libcamera/libcamera_sensor.h"

#include <errno.h>
#include <libcamera/camera.h>
#include <libcamera/camera_manager.h>
#include <libcamera/control_ids.h>
#include <libcamera/formats.h>
#include <libcamera/framebuffer_allocator.h>
#include <libcamera/request.h>
#include <libcamera/stream.h>
#include <string.h>
#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

#include "hal/frame_sequence.h"
#include "hal/libcamera/buffer_layout.h"
#include "hal/libcamera/exposure_hold.h"
#include "hal/libcamera/frame_check.h"
#include "hal/libcamera/libcamera_format.h"

namespace lb {

namespace lc = libcamera;

struct LibcameraSensor::Impl {
  struct Mapping {
    void* addr = nullptr;
    size_t length = 0;
  };
  // Where one buffer's planes lie in the process.
  struct Planes {
    const lc::FrameBuffer* buffer = nullptr;
    const uint8_t* plane[3] = {nullptr, nullptr, nullptr};
    ptrdiff_t stride[3] = {0, 0, 0};
  };

  explicit Impl(const LibcameraOptions& options)
      : wanted_id(options.camera_id ? options.camera_id : ""),
        hold_exposure(options.hold_exposure),
        reporter(options.log, options.log_context) {}

  std::string wanted_id;
  bool hold_exposure = true;
  HoldReporter reporter;

  std::unique_ptr<lc::CameraManager> manager;
  std::shared_ptr<lc::Camera> camera;
  bool acquired = false;
  std::unique_ptr<lc::CameraConfiguration> config;
  lc::Stream* stream = nullptr;
  std::unique_ptr<lc::FrameBufferAllocator> allocator;
  std::vector<std::unique_ptr<lc::Request>> requests;
  std::vector<Mapping> mappings;
  std::vector<Planes> planes;
  SensorConfig burst;
  PixelFormat format = PixelFormat::kRgb8;
  YuvRange range = YuvRange::kLimited;
  int32_t width = 0, height = 0;
  ptrdiff_t stride = 0;
  HeldControls held;
  std::string id;

  std::mutex mutex;
  std::condition_variable completed_cv;
  std::deque<lc::Request*> completed;  // guarded by mutex

  // Runs in libcamera's thread.
  void OnRequestCompleted(lc::Request* request) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      completed.push_back(request);
    }
    completed_cv.notify_one();
  }

  Status Error(Code code, const char* what, int ret) const {
    char text[96];
    int err = ret < 0 ? -ret : ret;
    return Status(code, "libcamera %s: %s failed: %s (errno %d)", id.c_str(), what,
                  strerror_r(err, text, sizeof(text)), err);
  }

  Status StartManager();
  // The configured camera (or the first one) among those the manager lists now.
  Status Find(std::shared_ptr<lc::Camera>* found) const;
  Status Open();
  Status ConfigureStream(const SensorConfig& config);
  Status MapBuffers();
  Status WaitRequest(lc::Request** request);
  Status Queue(lc::Request* request, const lc::ControlList* controls);
  Status Meter(lc::ControlList* fixed);
  Status Burst(FrameSink& sink);
  // What the burst does with a completed request (frame_check.h), as a Status when it ends it.
  Status Check(lc::Request* request, int32_t index, FrameSequence* sequence, bool* skip);
  Status Deliver(FrameSink& sink, lc::Request* request, int32_t index);
  void Release();
};

Status LibcameraSensor::Impl::StartManager() {
  if (manager) return Status::Ok();
  auto m = std::make_unique<lc::CameraManager>();
  if (int r = m->start(); r < 0) {
    char text[96];
    return Status(Code::kIoError, "libcamera: CameraManager::start failed: %s (errno %d)",
                  strerror_r(-r, text, sizeof(text)), -r);
  }
  manager = std::move(m);
  return Status::Ok();
}

Status LibcameraSensor::Impl::Find(std::shared_ptr<lc::Camera>* found) const {
  const std::vector<std::shared_ptr<lc::Camera>> cameras = manager->cameras();
  if (wanted_id.empty()) {
    if (cameras.empty()) return Status(Code::kNotFound, "libcamera: no camera found");
    *found = cameras.front();
    return Status::Ok();
  }
  for (const std::shared_ptr<lc::Camera>& c : cameras) {
    if (c->id() == wanted_id) {
      *found = c;
      return Status::Ok();
    }
  }
  std::string listed;
  for (const std::shared_ptr<lc::Camera>& c : cameras) {
    listed += (listed.empty() ? "'" : ", '") + c->id() + "'";
  }
  return Status(Code::kNotFound, "libcamera: no camera '%s' (found: %s)", wanted_id.c_str(),
                listed.empty() ? "none" : listed.c_str());
}

Status LibcameraSensor::Impl::Open() {
  LB_RETURN_IF_ERROR(StartManager());
  LB_RETURN_IF_ERROR(Find(&camera));
  id = camera->id();
  if (int r = camera->acquire(); r < 0) {
    camera.reset();
    return Error(r == -EBUSY ? Code::kBusy : Code::kIoError, "Camera::acquire", r);
  }
  acquired = true;
  camera->requestCompleted.connect(this, &Impl::OnRequestCompleted);
  return Status::Ok();
}

Status LibcameraSensor::Impl::ConfigureStream(const SensorConfig& wanted) {
  config = camera->generateConfiguration({lc::StreamRole::StillCapture});
  if (!config || config->size() != 1) {
    return Status(Code::kUnsupported, "libcamera %s: no still-capture configuration", id.c_str());
  }
  lc::StreamConfiguration& cfg = config->at(0);
  if (wanted.width > 0 && wanted.height > 0) {
    cfg.size = lc::Size(static_cast<unsigned>(wanted.width), static_cast<unsigned>(wanted.height));
  }
  lc::PixelFormat chosen = ChooseLibcameraFormat(cfg.pixelFormat, cfg.formats().pixelformats());
  if (!chosen.isValid()) {
    return Status(Code::kUnsupported,
                  "libcamera %s: offers no YUYV, NV12, YUV420, BGR888, RGB888, XBGR8888 or "
                  "XRGB8888 (%s)",
                  id.c_str(), cfg.pixelFormat.toString().c_str());
  }
  cfg.pixelFormat = chosen;
  // One buffer per frame where the handler allows, so a slow sink never starves the camera.
  if (static_cast<int32_t>(cfg.bufferCount) < wanted.frames) {
    cfg.bufferCount = static_cast<unsigned>(wanted.frames);
  }
  if (config->validate() == lc::CameraConfiguration::Invalid) {
    return Status(Code::kUnsupported, "libcamera %s: configuration %s rejected", id.c_str(),
                  cfg.toString().c_str());
  }
  if (!LibcameraToPixelFormat(cfg.pixelFormat, &format)) {
    return Status(Code::kUnsupported,
                  "libcamera %s: adjusted to %s, which the pipeline cannot read", id.c_str(),
                  cfg.toString().c_str());
  }
  if (int r = camera->configure(config.get()); r < 0) {
    return Error(Code::kIoError, "Camera::configure", r);
  }
  stream = cfg.stream();
  width = static_cast<int32_t>(cfg.size.width);
  height = static_cast<int32_t>(cfg.size.height);
  stride = static_cast<ptrdiff_t>(cfg.stride);
  range = LibcameraYuvRange(cfg.colorSpace);
  if (PlaneCount(format) > 1 && (width % 2 || height % 2)) {
    return Status(Code::kUnsupported, "libcamera %s: %s with odd size %dx%d", id.c_str(),
                  PixelFormatName(format), width, height);
  }
  return Status::Ok();
}

Status LibcameraSensor::Impl::MapBuffers() {
  allocator = std::make_unique<lc::FrameBufferAllocator>(camera);
  if (int r = allocator->allocate(stream); r < 0) {
    return Error(Code::kOutOfMemory, "FrameBufferAllocator::allocate", r);
  }
  const std::vector<std::unique_ptr<lc::FrameBuffer>>& buffers = allocator->buffers(stream);
  for (const std::unique_ptr<lc::FrameBuffer>& buffer : buffers) {
    // A vector before libcamera 0.6, a Span since: bound to a reference either way.
    const auto& bp = buffer->planes();
    BufferPlane listed[3];
    const size_t n = bp.size();
    for (size_t i = 0; i < n && i < 3; ++i) {
      listed[i] = {bp[i].fd.get(), bp[i].offset, bp[i].length};
    }
    PlaneLayout layout;
    Status laid = LayOutPlanes(format, width, height, stride, listed, n, &layout);
    if (!laid.ok()) return laid.Prefix("libcamera %s: ", id.c_str());
    // Planes may share one dmabuf: map each once, over the extent its planes cover.
    const uint8_t* base[3] = {nullptr, nullptr, nullptr};
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = 0; j < i && !base[i]; ++j) {
        if (listed[j].fd == listed[i].fd) base[i] = base[j];
      }
      if (base[i]) continue;
      const size_t extent = MappedExtent(listed, n, i);
      void* addr = mmap(nullptr, extent, PROT_READ, MAP_SHARED, listed[i].fd, 0);
      if (addr == MAP_FAILED) return Error(Code::kIoError, "mmap", errno);
      mappings.push_back({addr, extent});
      base[i] = static_cast<const uint8_t*>(addr);
    }
    Planes p;
    p.buffer = buffer.get();
    for (int32_t k = 0; k < layout.count; ++k) {
      p.plane[k] = base[layout.source[k]] + layout.offset[k];
      p.stride[k] = layout.stride[k];
    }
    planes.push_back(p);
  }

  for (const std::unique_ptr<lc::FrameBuffer>& buffer : buffers) {
    if (static_cast<int32_t>(requests.size()) >= burst.frames) break;
    std::unique_ptr<lc::Request> request = camera->createRequest(requests.size());
    if (!request)
      return Status(Code::kOutOfMemory, "libcamera %s: createRequest failed", id.c_str());
    if (int r = request->addBuffer(stream, buffer.get()); r < 0) {
      return Error(Code::kIoError, "Request::addBuffer", r);
    }
    requests.push_back(std::move(request));
  }
  if (requests.empty()) return Status(Code::kOutOfMemory, "libcamera %s: no buffers", id.c_str());
  return Status::Ok();
}

Status LibcameraSensor::Impl::WaitRequest(lc::Request** request) {
  std::unique_lock<std::mutex> lock(mutex);
  if (!completed_cv.wait_for(lock, std::chrono::milliseconds(burst.timeout_ms),
                             [&] { return !completed.empty(); })) {
    return Status(Code::kTimeout, "libcamera %s: no frame within %d ms", id.c_str(),
                  burst.timeout_ms);
  }
  *request = completed.front();
  completed.pop_front();
  if ((*request)->status() == lc::Request::RequestCancelled) {
    return Status(Code::kIoError, "libcamera %s: request cancelled (camera stopped or unplugged)",
                  id.c_str());
  }
  return Status::Ok();
}

Status LibcameraSensor::Impl::Queue(lc::Request* request, const lc::ControlList* controls) {
  request->reuse(lc::Request::ReuseBuffers);
  if (controls) request->controls().merge(*controls);
  if (int r = camera->queueRequest(request); r < 0) {
    return Error(Code::kIoError, "Camera::queueRequest", r);
  }
  return Status::Ok();
}

Status LibcameraSensor::Impl::Meter(lc::ControlList* fixed) {
  held = HeldControls();
  if (!hold_exposure) return Status::Ok();
  const lc::ControlInfoMap& available = camera->controls();
  if (!CanHoldAny(available)) {
    // Nothing to meter for; the note still says what drifts.
    held = HoldExposure(available, lc::ControlList(), fixed);
    reporter.Note(id.c_str(), held);
    return Status::Ok();
  }
  // Startup frames carry the algorithms' values before they converge: meter a later one.
  lc::Request* request = requests.front().get();
  lc::Request* done = nullptr;
  for (int32_t skipped = 0;; ++skipped) {
    LB_RETURN_IF_ERROR(Queue(request, nullptr));
    LB_RETURN_IF_ERROR(WaitRequest(&done));
    const lc::FrameBuffer* buffer = done->findBuffer(stream);
    if (!buffer || !IsStartupFrame(buffer->metadata()) || skipped >= kMaxStartupFrames) break;
  }
  held = HoldExposure(available, done->metadata(), fixed);
  reporter.Note(id.c_str(), held);
  return Status::Ok();
}

Status LibcameraSensor::Impl::Burst(FrameSink& sink) {
  lc::ControlList fixed(lc::controls::controls);
  LB_RETURN_IF_ERROR(Meter(&fixed));
  const lc::ControlList* controls = fixed.empty() ? nullptr : &fixed;
  size_t queued = 0;
  for (; queued < requests.size(); ++queued) {
    LB_RETURN_IF_ERROR(Queue(requests[queued].get(), controls));
  }
  FrameSequence sequence;
  int32_t skipped = 0;
  for (int32_t i = 0; i < burst.frames;) {
    lc::Request* request = nullptr;
    LB_RETURN_IF_ERROR(WaitRequest(&request));
    bool skip = false;
    LB_RETURN_IF_ERROR(Check(request, i, &sequence, &skip));
    if (skip) {
      if (++skipped > kMaxStartupFrames) {
        return Status(Code::kTimeout, "libcamera %s: still starting after %d frames", id.c_str(),
                      kMaxStartupFrames);
      }
      LB_RETURN_IF_ERROR(Queue(request, controls));  // it takes the skipped frame's place
      continue;
    }
    LB_RETURN_IF_ERROR(Deliver(sink, request, i));
    ++i;
    if (static_cast<int32_t>(queued) < burst.frames) {
      LB_RETURN_IF_ERROR(Queue(request, controls));
      ++queued;
    }
  }
  return Status::Ok();
}

Status LibcameraSensor::Impl::Check(lc::Request* request, int32_t index, FrameSequence* sequence,
                                    bool* skip) {
  *skip = false;
  const lc::FrameBuffer* buffer = request->findBuffer(stream);
  if (!buffer) {
    return Status(Code::kInternal, "libcamera %s: request without its buffer", id.c_str());
  }
  const lc::FrameMetadata& md = buffer->metadata();
  uint32_t missing = 0;
  switch (CheckFrame(md, index, sequence, &missing)) {
    case FrameVerdict::kDeliver:
      return Status::Ok();
    case FrameVerdict::kSkip:
      *skip = true;
      return Status::Ok();
    case FrameVerdict::kFailed:
      return Status(Code::kCorruptData,
                    "libcamera %s: frame %d (sequence %u) failed in the camera; burst abandoned",
                    id.c_str(), index, md.sequence);
    case FrameVerdict::kDropped:
      break;
  }
  return Status(Code::kCorruptData,
                "libcamera %s: frame %d: %u frame(s) dropped before sequence %u; burst abandoned",
                id.c_str(), index, missing, md.sequence);
}

Status LibcameraSensor::Impl::Deliver(FrameSink& sink, lc::Request* request, int32_t index) {
  const lc::FrameBuffer* buffer = request->findBuffer(stream);
  const Planes* p = nullptr;
  for (const Planes& candidate : planes) {
    if (candidate.buffer == buffer) p = &candidate;
  }
  if (!p) return Status(Code::kInternal, "libcamera %s: unknown buffer completed", id.c_str());
  const lc::FrameMetadata& md = buffer->metadata();
  FrameInfo info;
  info.index = index;
  info.format = format;
  info.width = width;
  info.height = height;
  info.timestamp_ns = static_cast<int64_t>(md.timestamp);
  info.sequence = md.sequence;
  info.range = range;
  FrameRows rows;
  rows.y0 = 0;
  rows.height = height;
  for (int32_t k = 0; k < 3; ++k) {
    rows.planes[k] = p->plane[k];
    rows.strides[k] = p->stride[k];
  }
  Status status = sink.BeginFrame(info);
  if (status.ok()) status = sink.Rows(rows);
  if (status.ok()) status = sink.EndFrame();
  if (!status.ok()) status.Prefix("libcamera %s: frame %d: ", id.c_str(), index);
  return status;
}

void LibcameraSensor::Impl::Release() {
  requests.clear();
  for (const Mapping& m : mappings) munmap(m.addr, m.length);
  mappings.clear();
  planes.clear();
  if (allocator && stream) (void)allocator->free(stream);
  allocator.reset();
  config.reset();
  stream = nullptr;
  if (camera) {
    camera->requestCompleted.disconnect(this);
    if (acquired) (void)camera->release();
  }
  acquired = false;
  camera.reset();
  std::lock_guard<std::mutex> lock(mutex);
  completed.clear();
}

LibcameraSensor::LibcameraSensor(const LibcameraOptions& options) : impl_(new Impl(options)) {}

LibcameraSensor::~LibcameraSensor() {
  Stop();
  if (impl_->manager) impl_->manager->stop();
}

Status LibcameraSensor::Configure(const SensorConfig& config, SensorMode* mode) {
  Stop();
  if (config.frames < 1 || config.frames > 64 || config.timeout_ms <= 0 || config.width < 0 ||
      config.height < 0) {
    return Status(Code::kInvalidArgument,
                  "libcamera: burst of %d frames, timeout %d ms, size %dx%d (frames 1..64, "
                  "timeout > 0)",
                  config.frames, config.timeout_ms, config.width, config.height);
  }
  impl_->burst = config;
  impl_->reporter.Reset();
  Status status = impl_->Open();
  if (status.ok()) status = impl_->ConfigureStream(config);
  if (status.ok()) status = impl_->MapBuffers();
  if (!status.ok()) {
    Stop();
    return status;
  }
  mode->width = impl_->width;
  mode->height = impl_->height;
  mode->format = impl_->format;
  mode->frames = config.frames;
  return Status::Ok();
}

Status LibcameraSensor::CaptureBurst(FrameSink& sink) {
  Impl& d = *impl_;
  if (!d.camera || d.requests.empty()) {
    return Status(Code::kInvalidArgument, "libcamera: CaptureBurst before Configure");
  }
  {
    std::lock_guard<std::mutex> lock(d.mutex);
    d.completed.clear();
  }
  if (int r = d.camera->start(); r < 0) return d.Error(Code::kIoError, "Camera::start", r);
  Status status = d.Burst(sink);
  // stop() completes (cancels) every request still queued, so all are free for the next burst.
  if (int r = d.camera->stop(); r < 0 && status.ok()) {
    status = d.Error(Code::kIoError, "Camera::stop", r);
  }
  std::lock_guard<std::mutex> lock(d.mutex);
  d.completed.clear();
  return status;
}

Status LibcameraSensor::Probe() {
  Impl& d = *impl_;
  if (d.camera) return Status::Ok();  // configured: acquired by this sensor
  LB_RETURN_IF_ERROR(d.StartManager());
  std::shared_ptr<lc::Camera> camera;
  return d.Find(&camera);
}

void LibcameraSensor::Stop() { impl_->Release(); }

bool LibcameraSensor::exposure_held() const { return impl_->held.exposure; }
bool LibcameraSensor::gain_held() const { return impl_->held.gain; }
bool LibcameraSensor::white_balance_held() const { return impl_->held.white_balance; }
const char* LibcameraSensor::camera_id() const { return impl_->id.c_str(); }

}  // namespace lb
