// EngineBackend: the web page's renderer in refocusd. One RefocusEngine, sized at start for the
// camera's photos, driven by ONE render thread at low priority (nice +10, inherited by the
// engine's workers) through a bounded queue:
//   - at most kQueueDepth requests wait; a newer preview of a photo replaces a waiting preview of
//     the same photo (its caller gets kBusy "superseded"), anything else beyond the bound is kBusy;
//   - a request still waiting after wait_limit_ms is withdrawn with kBusy (the camera is taking a
//     photo, or the page asks faster than the board renders);
//   - the last photo loaded stays loaded, so repeated taps on it do not read the file again;
//   - every render yields to the camera between strips (`camera_busy`).
// The HTTP handlers call it from their own threads; each call blocks until its request is done.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

#include "firmware/app/refocus_engine.h"
#include "firmware/web/refocus_backend.h"

namespace lb {

class Log;

class EngineBackend final : public RefocusBackend {
 public:
  static constexpr int kQueueDepth = 2;
  static constexpr int kNice = 10;

  // `width` x `height`: the largest photo the camera makes (the sensor size); `threads` as
  // JobOptions::threads. `log` and `camera_busy` are borrowed for the backend's life.
  EngineBackend(int32_t width, int32_t height, int32_t threads, Log* log,
                const std::atomic<bool>* camera_busy, int32_t wait_limit_ms = 20000);
  ~EngineBackend() override;
  EngineBackend(const EngineBackend&) = delete;
  EngineBackend& operator=(const EngineBackend&) = delete;

  // Waits until the render thread has sized the engine; not ok when it could not (the calls
  // below then return the same status).
  Status Ready();

  Status Describe(const char* path, PhotoInfo* info) override;
  Status Render(const char* path, const RefocusParams& params, bool preview,
                ByteSink* jpeg) override;
  Status Save(const char* path, const RefocusParams& params, const char* out_path) override;
  bool CameraBusy() const override {
    return camera_busy_ != nullptr && camera_busy_->load(std::memory_order_acquire);
  }

  // For tests and the log: files read so far, requests waiting, the render thread's id.
  int64_t loads() const { return loads_.load(); }
  int queued();
  pid_t render_tid() const { return tid_.load(); }
  size_t reserved_bytes() const { return engine_.reserved_bytes(); }

 private:
  enum class Kind : uint8_t { kDescribe, kRender, kSave };
  struct Request;

  Status Submit(Request* request);
  void Loop();
  Status Process(Request* request);
  Status EnsureLoaded(const char* path);

  RefocusEngine engine_;
  RefocusEngineConfig config_;
  Log* log_;
  const std::atomic<bool>* camera_busy_;
  int32_t wait_limit_ms_;

  std::mutex mutex_;
  std::condition_variable wake_;  // the render thread: a request or stop
  std::condition_variable done_;  // the callers: a request finished, or the engine is ready
  Request* queue_[kQueueDepth] = {};
  int count_ = 0;
  bool stop_ = false, ready_ = false;
  Status ready_status_;

  // The loaded photo, so a repeated request does not read it again (render thread only).
  char loaded_path_[4096] = {};
  dev_t loaded_dev_ = 0;
  ino_t loaded_ino_ = 0;
  int64_t loaded_mtime_ns_ = 0, loaded_size_ = 0;
  std::atomic<int64_t> loads_{0};
  std::atomic<pid_t> tid_{0};
  std::thread thread_;
};

// The page's normalised rectangle (displayed frame) as a focus region in the photo's stored
// pixels, for EXIF orientation 0..8; a zero-size rectangle is a tap (FocusAtPoint).
FocusRegion DisplayedToStored(const RefocusParams& params, int32_t width, int32_t height,
                              int32_t orientation);

}  // namespace lb
