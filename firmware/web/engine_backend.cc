#include "firmware/web/engine_backend.h"

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>

#include "algo/pipeline/pipeline.h"
#include "firmware/app/focus.h"
#include "firmware/codecs/exif.h"
#include "firmware/codecs/image_file.h"
#include "firmware/platform/log.h"

namespace lb {

struct EngineBackend::Request {
  Kind kind = Kind::kDescribe;
  const char* path = nullptr;
  const RefocusParams* params = nullptr;
  bool preview = false;
  ByteSink* sink = nullptr;
  PhotoInfo* info = nullptr;
  const char* out_path = nullptr;
  bool taken = false, done = false;
  Status status;
};

namespace {

double Ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since)
      .count();
}

const char* Base(const char* path) {
  const char* slash = strrchr(path, '/');
  return slash ? slash + 1 : path;
}

double Clamp01(float x) {
  return std::isfinite(x) ? std::clamp(static_cast<double>(x), 0.0, 1.0) : 0.5;
}

}  // namespace

FocusRegion DisplayedToStored(const RefocusParams& p, int32_t width, int32_t height,
                              int32_t orientation) {
  double s0, t0, s1, t1;
  ExifDisplayedToStored(orientation, Clamp01(p.x0), Clamp01(p.y0), &s0, &t0);
  ExifDisplayedToStored(orientation, Clamp01(p.x1), Clamp01(p.y1), &s1, &t1);
  const auto px = [](double f, int32_t size) {
    return std::clamp(static_cast<int32_t>(f * size), 0, size - 1);
  };
  const int32_t x0 = px(std::min(s0, s1), width), x1 = px(std::max(s0, s1), width);
  const int32_t y0 = px(std::min(t0, t1), height), y1 = px(std::max(t0, t1), height);
  if (x1 - x0 < 2 * kFocusPointHalfSide && y1 - y0 < 2 * kFocusPointHalfSide) {
    return FocusAtPoint((x0 + x1) / 2, (y0 + y1) / 2);  // a tap, or a drag too small to mean more
  }
  return {x0, y0, std::max(1, x1 - x0), std::max(1, y1 - y0)};
}

EngineBackend::EngineBackend(int32_t width, int32_t height, int32_t threads, Log* log,
                             const std::atomic<bool>* camera_busy, int32_t wait_limit_ms)
    : log_(log), camera_busy_(camera_busy), wait_limit_ms_(wait_limit_ms) {
  config_.max_width = width;
  config_.max_height = height;
  config_.threads = threads;
  config_.preview_side = kPreviewWidth;
  thread_ = std::thread([this] { Loop(); });
}

EngineBackend::~EngineBackend() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

Status EngineBackend::Ready() {
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return ready_; });
  return ready_status_;
}

int EngineBackend::queued() {
  std::lock_guard<std::mutex> lock(mutex_);
  return count_;
}

void EngineBackend::Loop() {
  const pid_t tid = static_cast<pid_t>(syscall(SYS_gettid));
  tid_ = tid;
  // Lower than the camera's threads; the engine's workers, started below, inherit it.
  errno = 0;
  const int base = getpriority(PRIO_PROCESS, static_cast<id_t>(tid));
  if (setpriority(PRIO_PROCESS, static_cast<id_t>(tid), std::min(19, base + kNice)) != 0 &&
      log_ != nullptr) {
    log_->Printf(LogLevel::kWarning, "web: cannot lower the render thread's priority: %s",
                 strerror(errno));
  }
  Status s = engine_.Configure(config_);
  engine_.set_camera_busy(camera_busy_);
  if (log_ != nullptr) {
    if (s.ok()) {
      log_->Printf(LogLevel::kInfo, "web: renderer ready for %dx%d photos, %zu MiB reserved",
                   config_.max_width, config_.max_height, engine_.reserved_bytes() >> 20);
    } else {
      log_->Printf(LogLevel::kError, "web: renderer: %s", s.message());
    }
  }
  std::unique_lock<std::mutex> lock(mutex_);
  ready_status_ = s;
  ready_ = true;
  done_.notify_all();
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || count_ > 0; });
    if (stop_) break;
    Request* r = queue_[0];
    for (int i = 1; i < count_; ++i) queue_[i - 1] = queue_[i];
    queue_[--count_] = nullptr;
    r->taken = true;
    lock.unlock();
    const Status status = Process(r);
    lock.lock();
    r->status = status;
    r->done = true;
    done_.notify_all();
  }
  // Whatever still waits is refused (the daemon is stopping).
  for (int i = 0; i < count_; ++i) {
    queue_[i]->status = Status(Code::kBusy, "web: the renderer is stopping");
    queue_[i]->done = true;
  }
  count_ = 0;
  done_.notify_all();
}

Status EngineBackend::Submit(Request* r) {
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return ready_; });
  if (!ready_status_.ok()) return ready_status_;
  if (stop_) return Status(Code::kBusy, "web: the renderer is stopping");
  if (r->kind == Kind::kRender && r->preview) {
    for (int i = 0; i < count_; ++i) {
      Request* old = queue_[i];
      if (old->kind == Kind::kRender && old->preview && strcmp(old->path, r->path) == 0) {
        old->status = Status(Code::kBusy, "web: preview superseded by a newer one");
        old->done = true;
        for (int j = i + 1; j < count_; ++j) queue_[j - 1] = queue_[j];
        queue_[--count_] = nullptr;
        done_.notify_all();
        break;
      }
    }
  }
  if (count_ == kQueueDepth) {
    return Status(Code::kBusy, "web: %d renders already wait", kQueueDepth);
  }
  queue_[count_++] = r;
  wake_.notify_one();
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::milliseconds(wait_limit_ms_);
  // The limit is for waiting in the queue; once the render thread has taken the request it holds
  // `r` until done, so the caller waits for that without a deadline (an expired one would wake
  // it at once, again and again).
  if (!done_.wait_until(lock, deadline, [r] { return r->done || r->taken; })) {
    for (int i = 0; i < count_; ++i) {
      if (queue_[i] != r) continue;
      for (int j = i + 1; j < count_; ++j) queue_[j - 1] = queue_[j];
      queue_[--count_] = nullptr;
      break;
    }
    return Status(Code::kBusy, "web: the renderer did not get to this within %d ms",
                  wait_limit_ms_);
  }
  done_.wait(lock, [r] { return r->done; });
  return r->status;
}

Status EngineBackend::EnsureLoaded(const char* path) {
  struct stat st;
  if (stat(path, &st) != 0) {
    return Status(errno == ENOENT ? Code::kNotFound : Code::kIoError, "%s: %s", path,
                  strerror(errno));
  }
  const int64_t mtime = static_cast<int64_t>(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
  if (engine_.loaded() && strcmp(path, loaded_path_) == 0 && st.st_dev == loaded_dev_ &&
      st.st_ino == loaded_ino_ && mtime == loaded_mtime_ns_ && st.st_size == loaded_size_) {
    return Status::Ok();
  }
  if (strlen(path) >= sizeof(loaded_path_)) {
    return Status(Code::kInvalidArgument, "web: path too long");
  }
  loaded_path_[0] = '\0';
  const auto t0 = std::chrono::steady_clock::now();
  ++loads_;
  Status s = engine_.Load(path);
  if (!s.ok()) {
    // A file the engine cannot take (larger than the camera's photos, an original or depth map
    // over its buffers, more extended-XMP pieces than it holds, no depth at all) is a photo the
    // page cannot refocus, not a fault of the server: Describe and every render decide it here.
    if (s.code() == Code::kNotFound || s.code() == Code::kIoError) return s;
    return Status(Code::kUnsupported, "%s", s.message());
  }
  snprintf(loaded_path_, sizeof(loaded_path_), "%s", path);
  loaded_dev_ = st.st_dev;
  loaded_ino_ = st.st_ino;
  loaded_mtime_ns_ = mtime;
  loaded_size_ = st.st_size;
  if (log_ != nullptr) {
    log_->Printf(LogLevel::kInfo, "web: loaded %s (%dx%d) in %.0f ms", Base(path),
                 engine_.photo().width, engine_.photo().height, Ms(t0));
  }
  return Status::Ok();
}

Status EngineBackend::Process(Request* r) {
  const auto t0 = std::chrono::steady_clock::now();
  Status s = EnsureLoaded(r->path);
  if (r->kind == Kind::kDescribe) {
    PhotoInfo& info = *r->info;
    info = PhotoInfo();
    if (!s.ok()) {
      // Not refocusable (or too large for the engine): still a photo the page can show.
      if (s.code() == Code::kNotFound || s.code() == Code::kIoError) return s;
      ImageFileInfo probe;
      if (!ProbeImageFile(r->path, &probe).ok()) return s;
      info.width = probe.width;
      info.height = probe.height;
      return Status::Ok();
    }
    const EnginePhoto& p = engine_.photo();
    const bool turned = ExifSwapsSides(p.orientation);
    info.width = turned ? p.height : p.width;
    info.height = turned ? p.width : p.height;
    info.refocusable = true;
    const FocusRegion& f = p.current.focus;
    double u = 0.5, v = 0.5;
    ExifStoredToDisplayed(p.orientation, (f.x + 0.5 * f.width) / p.width,
                          (f.y + 0.5 * f.height) / p.height, &u, &v);
    info.current.x0 = info.current.x1 = static_cast<float>(u);
    info.current.y0 = info.current.y1 = static_cast<float>(v);
    info.current.f_number = p.current.f_number;
    info.current.aperture = p.current.aperture;
    info.depth_guess = Pipeline::MostlyGuess(p.guess_permille);
    return Status::Ok();
  }
  LB_RETURN_IF_ERROR(s);
  const RefocusParams& q = *r->params;
  if (!(q.f_number >= RenderParams::kMinFNumber && q.f_number <= RenderParams::kMaxFNumber)) {
    return Status(Code::kInvalidArgument, "web: f/%.1f outside f/%g .. f/%g",
                  static_cast<double>(q.f_number), static_cast<double>(RenderParams::kMinFNumber),
                  static_cast<double>(RenderParams::kMaxFNumber));
  }
  const EnginePhoto& p = engine_.photo();
  RenderParams params;
  params.focus = DisplayedToStored(q, p.width, p.height, p.orientation);
  params.f_number = q.f_number;
  params.aperture = q.aperture;
  const char* what = "save";
  if (r->kind == Kind::kSave) {
    struct stat st;
    s = lstat(r->out_path, &st) == 0
            ? Status(Code::kInvalidArgument, "web: %s exists: a save never replaces a photo",
                     Base(r->out_path))
            : engine_.Save(params, r->out_path);
  } else {
    what = r->preview ? "preview" : "render";
    s = r->preview ? engine_.RenderPreview(params) : engine_.RenderFull(params);
    if (s.ok() && !r->sink->Append(engine_.output(), engine_.output_size())) {
      s = Status(Code::kOutOfMemory, "web: a %zu-byte JPEG is over the response's bound",
                 engine_.output_size());
    }
  }
  if (log_ != nullptr) {
    if (s.ok()) {
      log_->Printf(LogLevel::kInfo, "web: %s %s at %d,%d f/%.1f in %.0f ms", what, Base(r->path),
                   params.focus.x + params.focus.width / 2,
                   params.focus.y + params.focus.height / 2, static_cast<double>(params.f_number),
                   Ms(t0));
    } else {
      log_->Printf(LogLevel::kWarning, "web: %s %s: %s", what, Base(r->path), s.message());
    }
  }
  return s;
}

Status EngineBackend::Describe(const char* path, PhotoInfo* info) {
  Request r;
  r.kind = Kind::kDescribe;
  r.path = path;
  r.info = info;
  return Submit(&r);
}

Status EngineBackend::Render(const char* path, const RefocusParams& params, bool preview,
                             ByteSink* jpeg) {
  Request r;
  r.kind = Kind::kRender;
  r.path = path;
  r.params = &params;
  r.preview = preview;
  r.sink = jpeg;
  return Submit(&r);
}

Status EngineBackend::Save(const char* path, const RefocusParams& params, const char* out_path) {
  Request r;
  r.kind = Kind::kSave;
  r.path = path;
  r.params = &params;
  r.out_path = out_path;
  return Submit(&r);
}

}  // namespace lb
