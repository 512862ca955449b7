#include "firmware/daemon/camera_daemon.h"

#include <signal.h>
#include <sys/stat.h>

#include <cerrno>
#include <chrono>
#include <cstring>

namespace lb {

const char* CameraDaemon::StateName(State state) {
  switch (state) {
    case State::kIdle:
      return "idle";
    case State::kCapture:
      return "capture";
    case State::kProcess:
      return "process";
    case State::kSave:
      return "save";
  }
  return "?";
}

CameraDaemon::CameraDaemon(const DaemonConfig& config, Sensor* sensor, Button* button,
                           const Clock* clock, Log* log)
    : config_(config),
      options_(MakeJobOptions(config_)),
      sensor_(sensor),
      button_(button),
      clock_(clock),
      log_(log) {}

CameraDaemon::~CameraDaemon() {
  if (worker_.joinable()) Shutdown();
}

Status CameraDaemon::StageSensor::Configure(const SensorConfig& config, SensorMode* mode) {
  return owner_->sensor_->Configure(config, mode);
}

Status CameraDaemon::StageSensor::CaptureBurst(FrameSink& sink) {
  Status s = owner_->sensor_->CaptureBurst(sink);
  if (s.ok()) {
    owner_->SetState(State::kProcess);
  } else {
    owner_->capture_failed_ = true;
  }
  return s;
}

void CameraDaemon::StageObserver::OnStrip(const ConstPlanarU8&, int32_t y0, int32_t) {
  if (y0 == 0) owner_->SetState(State::kSave);
}

void CameraDaemon::SetState(State state) {
  std::lock_guard<std::mutex> lock(mutex_);
  state_ = state;
}

CameraDaemon::State CameraDaemon::state() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_;
}

CameraDaemon::Counts CameraDaemon::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counts_;
}

double CameraDaemon::SecondsSince(int64_t start_ns) const {
  return static_cast<double>(clock_->MonotonicNs() - start_ns) * 1e-9;
}

Status CameraDaemon::Start() {
  const char* dir = config_.output_dir.c_str();
  int removed = 0;
  Status s = namer_.Scan(dir, &removed);
  if (!s.ok()) log_->Printf(LogLevel::kWarning, "output: %s", s.message());
  if (removed > 0) {
    log_->Printf(LogLevel::kInfo,
                 "output: removed %d unfinished photo(s) left by an interrupted run", removed);
  }
  // Never created here: on a camera the folder is usually a card's mount point, and creating it
  // would hide photos on internal storage under the card once it is mounted.
  struct stat st;
  if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
    log_->Printf(LogLevel::kWarning, "output: %s is not a folder (yet): photos fail until it is",
                 dir);
  }
  // The worker never takes signals: they belong to the thread that waits on the button.
  sigset_t all, old;
  sigfillset(&all);
  pthread_sigmask(SIG_SETMASK, &all, &old);
  worker_ = std::thread(&CameraDaemon::Worker, this);
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  log_->Printf(LogLevel::kInfo, "ready: sensor %s%s%s, %dx%d, %d frames; photos to %s (next %04d)",
               sensor_->name(), config_.device.empty() ? "" : " ", config_.device.c_str(),
               config_.width, config_.height, config_.frames, dir, namer_.next_counter());
  return Status::Ok();
}

Status CameraDaemon::Run() {
  Status result;
  while (!stop_.load()) {
    ButtonEvent event = ButtonEvent::kNone;
    Status s = button_->Wait(kPollMs, &event);
    if (!s.ok()) {
      log_->Printf(LogLevel::kError, "button: %s", s.message());
      result = s;
      break;
    }
    if (event == ButtonEvent::kPress) OnPress();
    if (event == ButtonEvent::kHalfPress) OnHalfPress();
  }
  Shutdown();
  return result;
}

void CameraDaemon::OnPress() {
  std::lock_guard<std::mutex> lock(mutex_);
  ++counts_.presses;
  if (!busy_) {
    busy_ = start_ = true;
    state_ = State::kCapture;
    ++current_;
    log_->Printf(LogLevel::kInfo, "press: photo %d", current_);
    wake_.notify_one();
  } else if (config_.busy == BusyPolicy::kQueue && !queued_) {
    queued_ = true;
    ++counts_.queued;
    log_->Printf(LogLevel::kInfo, "press during photo %d (%s): queued", current_,
                 StateName(state_));
  } else {
    ++counts_.refused;
    log_->Printf(LogLevel::kWarning, "press during photo %d (%s): refused, %s", current_,
                 StateName(state_),
                 queued_ ? "one press is already queued" : "busy_press = refuse");
  }
}

void CameraDaemon::OnHalfPress() {
  std::lock_guard<std::mutex> lock(mutex_);
  log_->Printf(LogLevel::kDebug, "half press");
  if (!busy_) {
    configure_ = true;
    wake_.notify_one();
  }
}

void CameraDaemon::Shutdown() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (queued_) {
      log_->Printf(LogLevel::kWarning, "stopping: queued press dropped");
      queued_ = false;
    }
    if (busy_) log_->Printf(LogLevel::kInfo, "stopping: finishing photo %d first", current_);
    quit_ = true;
    wake_.notify_one();
  }
  if (worker_.joinable()) worker_.join();
  sensor_->Stop();
  const Counts c = counts();
  log_->Printf(LogLevel::kInfo, "stopped: %d photo(s) saved, %d failed, %d press(es) refused",
               c.saved, c.failed, c.refused);
}

void CameraDaemon::Worker() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return quit_ || start_ || configure_; });
    // A photo whose press was acknowledged is taken even when a stop came meanwhile.
    if (start_) {
      start_ = configure_ = false;
      const int32_t number = current_;
      lock.unlock();
      TakePhoto(number);
      lock.lock();
      if (queued_ && !quit_) {
        queued_ = false;
        start_ = true;
        state_ = State::kCapture;
        ++current_;
        log_->Printf(LogLevel::kInfo, "queued press: photo %d", current_);
      } else {
        busy_ = false;
        state_ = State::kIdle;
        idle_.notify_all();
      }
      continue;
    }
    if (quit_) break;
    configure_ = false;
    if (configured_) continue;
    lock.unlock();
    const int64_t t0 = clock_->MonotonicNs();
    Status s = ConfigureSensor();
    if (s.ok()) {
      log_->Printf(LogLevel::kInfo, "half press: sensor ready in %.0f ms", SecondsSince(t0) * 1e3);
    } else {
      log_->Printf(LogLevel::kError, "half press: sensor not ready: %s", s.message());
    }
    lock.lock();
  }
}

Status CameraDaemon::ConfigureSensor() {
  Status s = job_.Configure(&stage_sensor_, options_);
  configured_ = s.ok();
  if (!s.ok()) sensor_->Stop();
  return s;
}

void CameraDaemon::TakePhoto(int32_t number) {
  Status s;
  if (!configured_) s = ConfigureSensor();
  char path[PhotoNamer::kMaxDir + 64];
  if (s.ok()) {
    tm now;
    clock_->LocalTime(&now);
    s = namer_.Next(now, path, sizeof(path));
  }
  if (!s.ok()) {
    log_->Printf(LogLevel::kError, "photo %d: not taken: %s", number, s.message());
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_.failed;
    return;
  }
  JobReport report;
  for (int32_t attempt = 0;; ++attempt) {
    SetState(State::kCapture);
    capture_failed_ = false;
    s = job_.Run(path, &report, &stage_observer_);
    if (s.ok()) break;
    if (capture_failed_ && s.code() == Code::kCorruptData && attempt < config_.capture_retries) {
      log_->Printf(LogLevel::kWarning, "photo %d: %s; taking a fresh burst (retry %d of %d)",
                   number, s.message(), attempt + 1, config_.capture_retries);
      continue;
    }
    if (capture_failed_) {
      // Whatever went wrong (an unplugged camera, a stalled driver), a fresh open is the surest
      // way back.
      sensor_->Stop();
      configured_ = false;
    }
    log_->Printf(LogLevel::kError, "photo %d: not saved: %s%s", number, s.message(),
                 capture_failed_ ? " (the sensor is reopened at the next press)" : "");
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_.failed;
    return;
  }
  namer_.Used();
  if (!report.warning.ok()) {
    log_->Printf(LogLevel::kWarning, "photo %d: not blurred (no depth from this burst): %s", number,
                 report.warning.message());
  }
  log_->Printf(LogLevel::kInfo,
               "photo %d: saved %s (%dx%d; capture %.2f s, depth %.2f s, render and save %.2f s)",
               number, path, report.width, report.height, report.capture_s, report.depth_s,
               report.render_s);
  std::lock_guard<std::mutex> lock(mutex_);
  ++counts_.saved;
}

bool CameraDaemon::WaitIdle(int32_t timeout_ms) {
  std::unique_lock<std::mutex> lock(mutex_);
  return idle_.wait_for(lock, std::chrono::milliseconds(timeout_ms), [this] { return !busy_; });
}

}  // namespace lb
