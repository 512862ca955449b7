#include "firmware/daemon/camera_daemon.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>

#include "firmware/daemon/startup_checks.h"
#include "firmware/platform/signals_blocked.h"

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
  {
    // The worker never takes signals: they belong to the thread that waits on the button.
    const SignalsBlocked blocked;
    worker_ = std::thread(&CameraDaemon::Worker, this);
  }
  (void)CheckReady(true);
  return Status::Ok();
}

bool CameraDaemon::Note(const Status& status, Problem* problem, const char* fixed) {
  if (status.ok()) {
    if (problem->text[0] == '\0') return false;
    log_->Printf(LogLevel::kInfo, "%s", fixed);
    problem->text[0] = '\0';
    return true;
  }
  if (strcmp(problem->text, status.message()) == 0) return false;
  log_->Printf(LogLevel::kError, "%s", status.message());
  snprintf(problem->text, sizeof(problem->text), "%s", status.message());
  return true;
}

void CameraDaemon::Problems(char* out, size_t size) const {
  snprintf(out, size, "%s%s%s", camera_problem_.text,
           camera_problem_.text[0] && folder_problem_.text[0] ? "; " : "", folder_problem_.text);
}

bool CameraDaemon::Idle() {
  std::lock_guard<std::mutex> lock(mutex_);
  return !busy_;
}

bool CameraDaemon::CheckReady(bool scheduled) {
  // A missing camera or a read-only card must show before the first press, not as its photo
  // failing. The folder is never created here: on a camera it is usually a card's mount point,
  // and creating it would hide photos on internal storage under the card once it is mounted.
  const Status camera = sensor_->Probe();
  const Status folder = CheckPhotoFolder(config_.output_dir.c_str());
  char fixed[Status::kMaxMessage + 64];
  snprintf(fixed, sizeof(fixed), "sensor %s%s%s: the camera is there now", sensor_->name(),
           config_.device.empty() ? "" : " ", config_.device.c_str());
  bool changed = Note(camera, &camera_problem_, fixed);
  snprintf(fixed, sizeof(fixed), "output folder %s: writable now", config_.output_dir.c_str());
  changed = Note(folder, &folder_problem_, fixed) || changed;
  if (camera.ok() && folder.ok()) {
    BecomeReady();
    return true;
  }
  // A problem that changed suggests someone at work on the camera: look again soon. One that
  // stays is looked at less and less often, and not logged again. A press's check leaves the
  // schedule alone unless it found a change.
  if (changed || scheduled) {
    retry_ms_ = changed ? kFirstRetryMs : std::min(2 * retry_ms_, kMaxRetryMs);
    next_check_ns_ = clock_->MonotonicNs() + int64_t{retry_ms_} * 1000000;
  }
  if (changed) {
    log_->Printf(LogLevel::kWarning,
                 "not ready: will check again in %d s, backing off to every %d s; a press checks "
                 "at once",
                 retry_ms_ / 1000, kMaxRetryMs / 1000);
  }
  return false;
}

void CameraDaemon::BecomeReady() {
  // Scanned only now: a card mounted since the start holds the photos the count continues from.
  const char* dir = config_.output_dir.c_str();
  int removed = 0;
  Status s = namer_.Scan(dir, &removed);
  if (!s.ok()) log_->Printf(LogLevel::kWarning, "output: %s", s.message());
  if (removed > 0) {
    log_->Printf(LogLevel::kInfo,
                 "output: removed %d unfinished photo(s) left by an interrupted run", removed);
  }
  ready_.store(true);
  log_->Printf(LogLevel::kInfo, "ready: sensor %s%s%s, %dx%d, %d frames; photos to %s (next %04d)",
               sensor_->name(), config_.device.empty() ? "" : " ", config_.device.c_str(),
               config_.job.sensor.width, config_.job.sensor.height, config_.job.sensor.frames, dir,
               namer_.next_counter());
}

Status CameraDaemon::Run() {
  Status result;
  while (!stop_.load()) {
    // A capture failed: the camera may be gone. Checked from here, with the worker idle, as at
    // the start (the sensor is not probed while a photo may use it).
    if (recheck_.load() && Idle()) {
      recheck_.store(false);
      ready_.store(false);
      retry_ms_ = kFirstRetryMs;
      next_check_ns_ = clock_->MonotonicNs();
    }
    int32_t wait_ms = kPollMs;
    if (!ready_.load()) {
      const int64_t left_ns = next_check_ns_ - clock_->MonotonicNs();
      if (left_ns <= 0) {
        (void)CheckReady(true);
        continue;
      }
      // Rounded up, so the wait never ends just before the check is due.
      wait_ms = static_cast<int32_t>(std::min<int64_t>(kPollMs, (left_ns + 999999) / 1000000));
    }
    ButtonEvent event = ButtonEvent::kNone;
    Status s = button_->Wait(wait_ms, &event);
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
  if (!ready_.load() && !CheckReady(false)) {
    char why[2 * Status::kMaxMessage + 8];
    Problems(why, sizeof(why));
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_.presses;
    ++counts_.refused;
    log_->Printf(LogLevel::kWarning, "press: refused, not ready: %s", why);
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ++counts_.presses;
  if (!busy_) {
    busy_ = start_ = true;
    camera_busy_.store(true);
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
  // The worker must not touch the sensor while the checks may still probe it from this thread.
  if (!ready_.load() && !CheckReady(false)) {
    log_->Printf(LogLevel::kDebug, "half press: not ready");
    return;
  }
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
        camera_busy_.store(false);
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
  if (!configured_) {
    s = ConfigureSensor();
    if (!s.ok()) recheck_.store(true);
  }
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
      recheck_.store(true);
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
  if (report.hint != nullptr) log_->Printf(LogLevel::kWarning, "photo %d: %s", number, report.hint);
  log_->Printf(LogLevel::kInfo,
               "photo %d: saved %s (%dx%d; capture %.2f s, depth %.2f s of which motion %.2f s, "
               "render and save %.2f s)",
               number, path, report.width, report.height, report.capture_s, report.depth_s,
               report.motion_s, report.render_s);
  std::lock_guard<std::mutex> lock(mutex_);
  ++counts_.saved;
}

bool CameraDaemon::WaitIdle(int32_t timeout_ms) {
  std::unique_lock<std::mutex> lock(mutex_);
  return idle_.wait_for(lock, std::chrono::milliseconds(timeout_ms), [this] { return !busy_; });
}

}  // namespace lb
