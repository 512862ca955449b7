// The daemon's state machine: idle -> capture -> process -> save -> idle, one photo per press.
//
// The caller's thread waits on the button (Run) while one worker thread takes the photos, so a
// press that arrives while a photo is being taken is seen at once and either queued (at most
// one) or refused, with a log line either way. A photo that fails (the sensor times out, a frame
// is dropped, the card is full) is logged and leaves the daemon idle and ready; after a capture
// failure the sensor is closed and opened again at the next press. A dropped frame first gets
// `capture_retries` fresh bursts, since the depth stage needs evenly spaced views.
//
// Before the first photo the daemon checks what it can without capturing: the camera is there
// and is one its backend can drive (Sensor::Probe), and the photo folder can be written
// (CheckPhotoFolder). Each problem is logged once, and "ready" only when all hold. Until then the
// checks run again after 1 s, doubling to every 30 s (a camera plugged in or a card mounted later
// is found without polling the device all the time); a line is logged only when a problem
// appears, changes or goes away. A press while not ready checks at once: it takes its photo if
// everything holds now, else it is refused with the reason. A photo whose capture fails sends
// the daemon back to these checks once the worker is idle (at once, then on the same schedule):
// a camera unplugged since makes it not ready, so presses are refused with the reason until the
// camera is back; one still there makes it ready again at once. A card that goes away fails the
// photos, each with its log line.
//
// One Job is configured once (on the first half press or press) and reused for every photo, so
// nothing grows from press to press. Sensor, button, clock and log are borrowed; tests inject a
// synthetic sensor, a scripted button and a fixed clock.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

#include "firmware/app/job.h"
#include "firmware/daemon/clock.h"
#include "firmware/daemon/config.h"
#include "firmware/daemon/photo_namer.h"
#include "firmware/platform/log.h"
#include "hal/button.h"
#include "hal/sensor.h"

namespace lb {

class CameraDaemon {
 public:
  enum class State : uint8_t { kIdle, kCapture, kProcess, kSave };
  static const char* StateName(State state);

  struct Counts {
    int32_t presses = 0, saved = 0, failed = 0, queued = 0, refused = 0;
  };

  // How often Run looks at the stop flag while the button is quiet.
  static constexpr int32_t kPollMs = 200;
  // The wait before the checks run again while not ready: the first, doubled at each failed run
  // that found the same problems, and at most the last.
  static constexpr int32_t kFirstRetryMs = 1000;
  static constexpr int32_t kMaxRetryMs = 30000;

  CameraDaemon(const DaemonConfig& config, Sensor* sensor, Button* button, const Clock* clock,
               Log* log);
  ~CameraDaemon();
  CameraDaemon(const CameraDaemon&) = delete;
  CameraDaemon& operator=(const CameraDaemon&) = delete;

  // Starts the worker and runs the checks. When they hold: scans the output folder (removing
  // temporaries a killed run left) and logs "ready"; otherwise logs each problem and that it will
  // check again. Not being ready is no error: Run keeps checking.
  Status Start();
  // Handles button events (and, while not ready, runs the checks when due) until RequestStop or
  // a button failure. Then the photo in progress (its press acknowledged) is finished, a queued
  // press is dropped (logged), the worker ends and the sensor is released.
  Status Run();
  // Async-signal-safe (a signal handler may call it).
  void RequestStop() { stop_.store(true); }

  State state() const;
  Counts counts() const;
  // Every check holds, "ready" was logged.
  bool ready() const { return ready_.load(); }
  // Set from a press until its photo (and a queued one) is done: other work on the board (the
  // web page's renders) waits while it is set, so the camera comes first.
  const std::atomic<bool>* camera_busy() const { return &camera_busy_; }
  // Tests: waits until no photo is in progress or queued; false on timeout.
  bool WaitIdle(int32_t timeout_ms);

 private:
  // Forwards to the real sensor and notes where a burst ends (capture -> process).
  class StageSensor : public Sensor {
   public:
    explicit StageSensor(CameraDaemon* owner) : owner_(owner) {}
    const char* name() const override { return owner_->sensor_->name(); }
    Status Configure(const SensorConfig& config, SensorMode* mode) override;
    Status CaptureBurst(FrameSink& sink) override;
    void Stop() override { owner_->sensor_->Stop(); }

   private:
    CameraDaemon* owner_;
  };
  // Notes the first strip going to the encoder (process -> save).
  class StageObserver : public StripObserver {
   public:
    explicit StageObserver(CameraDaemon* owner) : owner_(owner) {}
    void OnStrip(const ConstPlanarU8& strip, int32_t y0, int32_t rows) override;

   private:
    CameraDaemon* owner_;
  };

  // One remembered problem of a check: "" while it holds.
  struct Problem {
    char text[Status::kMaxMessage] = {};
  };

  void OnPress();
  void OnHalfPress();
  // Runs the checks and logs what changed since the last run; on success scans the folder and
  // logs "ready". `scheduled`: the run the schedule asked for (else a press's), which sets the
  // next. Run thread only (Start before Run starts).
  bool CheckReady(bool scheduled);
  bool Idle();  // no photo accepted and unfinished
  // Logs a new or changed problem (error), or `fixed` (info) when a problem went away; true when
  // anything changed.
  bool Note(const Status& status, Problem* problem, const char* fixed);
  void BecomeReady();
  // Both problems, "; " between, for the line that refuses a press.
  void Problems(char* out, size_t size) const;
  void Shutdown();
  void Worker();
  void TakePhoto(int32_t number);
  Status ConfigureSensor();
  void SetState(State state);
  double SecondsSince(int64_t start_ns) const;

  const DaemonConfig config_;
  const JobOptions options_;
  Sensor* sensor_;
  Button* button_;
  const Clock* clock_;
  Log* log_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> ready_{false};
  std::atomic<bool> camera_busy_{false};  // mirrors busy_ for readers that take no lock
  std::atomic<bool> recheck_{false};      // set by the worker: a capture failed

  // Run thread only, until ready: the checks' last findings and schedule.
  Problem camera_problem_, folder_problem_;
  int32_t retry_ms_ = kFirstRetryMs;
  int64_t next_check_ns_ = 0;

  // Worker-only.
  Job job_;
  StageSensor stage_sensor_{this};
  StageObserver stage_observer_{this};
  PhotoNamer namer_;
  bool configured_ = false;
  bool capture_failed_ = false;

  // Shared, under mutex_.
  mutable std::mutex mutex_;
  std::condition_variable wake_;  // worker: something to do
  std::condition_variable idle_;  // WaitIdle
  State state_ = State::kIdle;
  bool busy_ = false;   // a photo accepted and not finished
  bool start_ = false;  // the worker should start photo current_
  bool queued_ = false;
  bool configure_ = false;
  bool quit_ = false;
  int32_t current_ = 0;  // number of the photo in progress (1, 2, ...)
  Counts counts_;
  std::thread worker_;
};

}  // namespace lb
