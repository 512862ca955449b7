// The daemon's state machine without hardware: the synthetic sensor (with scripted faults and a
// gate that holds a burst open), a button the test presses, a fixed clock and a recording log.
#include "firmware/daemon/camera_daemon.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "sim/synthetic/synthetic_sensor.h"
#include "tests/firmware/codecs/jpeg_test_util.h"

namespace lb {
namespace {

using std::chrono::milliseconds;

class TestButton : public Button {
 public:
  void Push(ButtonEvent e) {
    std::lock_guard<std::mutex> lock(mutex_);
    events_.push_back(e);
    cv_.notify_all();
  }
  void Break() {
    std::lock_guard<std::mutex> lock(mutex_);
    broken_ = true;
    cv_.notify_all();
  }
  Status Wait(int32_t timeout_ms, ButtonEvent* event) override {
    ++waits;
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_for(lock, milliseconds(timeout_ms), [this] { return broken_ || !events_.empty(); });
    *event = ButtonEvent::kNone;
    if (broken_) return Status(Code::kNotFound, "test button: the input device went away");
    if (!events_.empty()) {
      *event = events_.front();
      events_.pop_front();
    }
    return Status::Ok();
  }

  // Calls of Wait begun: the daemon enters one after each of its checks.
  std::atomic<int> waits{0};

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<ButtonEvent> events_;
  bool broken_ = false;
};

enum class Fault { kNone, kTimeout, kDrop };

// The synthetic sensor with faults per burst and a gate: while closed, a burst waits at its start.
// Its camera can be absent (Probe fails as a missing V4L2 node does); each Probe is counted and,
// when a clock is set, its time noted.
class TestSensor : public Sensor {
 public:
  const char* name() const override { return "test"; }
  Status Probe() override {
    std::lock_guard<std::mutex> lock(mutex_);
    ++probes;
    if (clock != nullptr) probe_ns_.push_back(clock->MonotonicNs());
    if (!present) return Status(Code::kNotFound, "camera test0: no such device");
    return Status::Ok();
  }
  Status Configure(const SensorConfig& config, SensorMode* mode) override {
    ++configures;
    return inner_.Configure(config, mode);
  }
  Status CaptureBurst(FrameSink& sink) override {
    std::unique_lock<std::mutex> lock(mutex_);
    ++bursts_started_;
    cv_.notify_all();
    cv_.wait(lock, [this] { return open_; });
    const Fault fault = faults_.empty() ? Fault::kNone : faults_.front();
    if (!faults_.empty()) faults_.pop_front();
    lock.unlock();
    if (fault == Fault::kTimeout) return Status(Code::kTimeout, "test: no frame within 2000 ms");
    if (fault == Fault::kNone) return inner_.CaptureBurst(sink);
    DropAfter drop(&sink, 2);
    return inner_.CaptureBurst(drop);
  }
  void Stop() override { ++stops; }

  void AddFault(Fault f) {
    std::lock_guard<std::mutex> lock(mutex_);
    faults_.push_back(f);
  }
  void SetOpen(bool open) {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = open;
    cv_.notify_all();
  }
  bool WaitBursts(int n) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, milliseconds(10000), [&] { return bursts_started_ >= n; });
  }

  // Milliseconds between consecutive probes.
  std::vector<int64_t> ProbeGapsMs() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<int64_t> gaps;
    for (size_t i = 1; i < probe_ns_.size(); ++i) {
      gaps.push_back((probe_ns_[i] - probe_ns_[i - 1]) / 1000000);
    }
    return gaps;
  }

  std::atomic<int> configures{0}, stops{0}, probes{0};
  std::atomic<bool> present{true};
  const Clock* clock = nullptr;

 private:
  // Passes frames on until `index`, then reports it lost, as a driver's sequence gap does.
  class DropAfter : public FrameSink {
   public:
    DropAfter(FrameSink* inner, int32_t index) : inner_(inner), index_(index) {}
    Status BeginFrame(const FrameInfo& info) override {
      if (info.index == index_) {
        return Status(Code::kCorruptData, "test: frame %d: 1 frame(s) dropped", index_);
      }
      return inner_->BeginFrame(info);
    }
    Status Rows(const FrameRows& rows) override { return inner_->Rows(rows); }
    Status EndFrame() override { return inner_->EndFrame(); }

   private:
    FrameSink* inner_;
    int32_t index_;
  };

  SyntheticSensor inner_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Fault> faults_;
  bool open_ = true;
  int bursts_started_ = 0;
  std::vector<int64_t> probe_ns_;
};

// Photos named at a fixed second. Monotonic time is the system's, or, once Freeze was called,
// stands still except where the test (or a SimulatedButton) moves it on.
class FixedClock : public Clock {
 public:
  int64_t MonotonicNs() const override {
    const int64_t frozen = frozen_ns_.load();
    return frozen >= 0 ? frozen : system_.MonotonicNs();
  }
  void Freeze(int64_t ns) { frozen_ns_.store(ns); }
  void Advance(int64_t ns) { frozen_ns_.fetch_add(ns); }
  void LocalTime(tm* out) const override {
    *out = tm{};
    out->tm_year = 2026 - 1900;
    out->tm_mon = 2;
    out->tm_mday = 14;
    out->tm_hour = 15;
    out->tm_min = 9;
    out->tm_sec = 26;
  }

 private:
  SystemClock system_;
  std::atomic<int64_t> frozen_ns_{-1};
};

// A quiet button in simulated time: each wait returns at once and moves the frozen clock on by
// its timeout, until the clock reaches `end_ns`; from then on it waits in real time and the clock
// stands still. So minutes of a daemon's waiting pass in milliseconds.
class SimulatedButton : public Button {
 public:
  SimulatedButton(FixedClock* clock, int64_t end_ns) : clock_(clock), end_ns_(end_ns) {}
  Status Wait(int32_t timeout_ms, ButtonEvent* event) override {
    *event = ButtonEvent::kNone;
    if (clock_->MonotonicNs() >= end_ns_) {
      std::this_thread::sleep_for(milliseconds(timeout_ms));
      return Status::Ok();
    }
    clock_->Advance(
        std::min<int64_t>(int64_t{timeout_ms} * 1000000, end_ns_ - clock_->MonotonicNs()));
    return Status::Ok();
  }

 private:
  FixedClock* clock_;
  int64_t end_ns_;
};

class RecordingSink : public LogSink {
 public:
  void Write(LogLevel level, const char* text) override {
    std::lock_guard<std::mutex> lock(mutex_);
    lines_.push_back(std::string(LogLevelName(level)) + ": " + text);
  }
  int Count(const std::string& part) {
    std::lock_guard<std::mutex> lock(mutex_);
    return static_cast<int>(std::count_if(lines_.begin(), lines_.end(), [&](const std::string& l) {
      return l.find(part) != std::string::npos;
    }));
  }
  bool WaitFor(const std::string& part, int times = 1) {
    for (int i = 0; i < 1000; ++i) {
      if (Count(part) >= times) return true;
      std::this_thread::sleep_for(milliseconds(10));
    }
    return false;
  }
  std::string All() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::string all;
    for (const auto& l : lines_) all += l + "\n";
    return all;
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> lines_;
};

const char kFirst[] = "IMG_20260314_150926_0001.jpg";
const char kSecond[] = "IMG_20260314_150926_0002.jpg";

class CameraDaemonTest : public ::testing::Test {
 protected:
  CameraDaemonTest() {
    config_.backend = Backend::kSynthetic;
    config_.job.sensor.width = 128;
    config_.job.sensor.height = 96;
    config_.job.sensor.frames = 5;
    config_.job.pipeline.labels = 8;
    config_.output_dir = dir_.dir();
    config_.log_level = LogLevel::kDebug;
  }
  ~CameraDaemonTest() override { Stop(); }

  void StartDaemon(Button* button = nullptr) {
    daemon_ = std::make_unique<CameraDaemon>(config_, &sensor_, button ? button : &button_, &clock_,
                                             &log_);
    ASSERT_TRUE(daemon_->Start().ok());
    runner_ = std::thread([this] { run_status_ = daemon_->Run(); });
  }
  void Stop() {
    if (!runner_.joinable()) return;
    daemon_->RequestStop();
    runner_.join();
  }
  void PressAndWait() {
    // The press must be seen before WaitIdle can mean "done".
    const int presses = daemon_->counts().presses;
    button_.Push(ButtonEvent::kPress);
    for (int i = 0; i < 500 && daemon_->counts().presses == presses; ++i) {
      std::this_thread::sleep_for(milliseconds(10));
    }
    ASSERT_TRUE(daemon_->WaitIdle(30000)) << sink_.All();
  }
  // Photo names in the folder, sorted; temporaries included (they start with a dot).
  std::vector<std::string> Files() {
    auto names = dir_.Entries();
    std::sort(names.begin(), names.end());
    return names;
  }
  void ExpectWholeJpeg(const std::string& name) {
    int32_t w = 0, h = 0;
    std::vector<uint8_t> ycc;
    std::string error;
    ASSERT_TRUE(test::DecodeYcc(test::ReadFile(dir_.Path(name)), &w, &h, &ycc, &error))
        << name << ": " << error;
    EXPECT_EQ(w, config_.job.sensor.width);
    EXPECT_EQ(h, config_.job.sensor.height);
  }

  test::ScratchDir dir_;
  DaemonConfig config_;
  TestSensor sensor_;
  TestButton button_;
  FixedClock clock_;
  RecordingSink sink_;
  Log log_{&sink_, LogLevel::kDebug};
  std::unique_ptr<CameraDaemon> daemon_;
  std::thread runner_;
  Status run_status_;
};

TEST_F(CameraDaemonTest, PressSavesOneWholeJpegNamedByTimeAndCounter) {
  StartDaemon();
  PressAndWait();
  PressAndWait();
  Stop();
  EXPECT_TRUE(run_status_.ok()) << run_status_.message();
  EXPECT_EQ(Files(), (std::vector<std::string>{kFirst, kSecond}));
  ExpectWholeJpeg(kFirst);
  ExpectWholeJpeg(kSecond);
  EXPECT_EQ(sink_.Count("photo 1: saved " + dir_.Path(kFirst)), 1) << sink_.All();
  EXPECT_EQ(sink_.Count("stopped: 2 photo(s) saved, 0 failed"), 1) << sink_.All();
  EXPECT_EQ(daemon_->state(), CameraDaemon::State::kIdle);
  // One configuration serves every press.
  EXPECT_EQ(sensor_.configures.load(), 1);
}

TEST_F(CameraDaemonTest, HalfPressReadiesTheSensorBeforeThePress) {
  StartDaemon();
  button_.Push(ButtonEvent::kHalfPress);
  ASSERT_TRUE(sink_.WaitFor("half press: sensor ready")) << sink_.All();
  EXPECT_EQ(sensor_.configures.load(), 1);
  PressAndWait();
  EXPECT_EQ(sensor_.configures.load(), 1);
  EXPECT_EQ(Files(), std::vector<std::string>{kFirst});
}

TEST_F(CameraDaemonTest, PressesWhileBusyAreQueuedOnceThenRefused) {
  StartDaemon();
  sensor_.SetOpen(false);
  button_.Push(ButtonEvent::kPress);
  ASSERT_TRUE(sensor_.WaitBursts(1));
  button_.Push(ButtonEvent::kPress);
  button_.Push(ButtonEvent::kPress);
  ASSERT_TRUE(sink_.WaitFor("refused")) << sink_.All();
  EXPECT_EQ(sink_.Count("info: press during photo 1 (capture): queued"), 1) << sink_.All();
  EXPECT_EQ(sink_.Count("warning: press during photo 1 (capture): refused, one press is already "
                        "queued"),
            1)
      << sink_.All();
  sensor_.SetOpen(true);
  ASSERT_TRUE(daemon_->WaitIdle(30000));
  EXPECT_EQ(Files(), (std::vector<std::string>{kFirst, kSecond}));
  const CameraDaemon::Counts c = daemon_->counts();
  EXPECT_EQ(c.presses, 3);
  EXPECT_EQ(c.saved, 2);
  EXPECT_EQ(c.queued, 1);
  EXPECT_EQ(c.refused, 1);
}

TEST_F(CameraDaemonTest, RefusePolicyRefusesEveryPressWhileBusy) {
  config_.busy = BusyPolicy::kRefuse;
  StartDaemon();
  sensor_.SetOpen(false);
  button_.Push(ButtonEvent::kPress);
  ASSERT_TRUE(sensor_.WaitBursts(1));
  button_.Push(ButtonEvent::kPress);
  ASSERT_TRUE(sink_.WaitFor("refused, busy_press = refuse")) << sink_.All();
  sensor_.SetOpen(true);
  ASSERT_TRUE(daemon_->WaitIdle(30000));
  EXPECT_EQ(Files(), std::vector<std::string>{kFirst});
}

TEST_F(CameraDaemonTest, SensorTimeoutIsLoggedAndTheNextPressWorks) {
  sensor_.AddFault(Fault::kTimeout);
  StartDaemon();
  PressAndWait();
  EXPECT_EQ(Files(), std::vector<std::string>{});  // no photo, no temporary
  EXPECT_EQ(sink_.Count("error: photo 1: not saved: test: no frame within 2000 ms (the sensor is "
                        "reopened at the next press)"),
            1)
      << sink_.All();
  EXPECT_EQ(sensor_.stops.load(), 1);
  EXPECT_EQ(daemon_->state(), CameraDaemon::State::kIdle);
  PressAndWait();
  EXPECT_EQ(sensor_.configures.load(), 2);
  EXPECT_EQ(Files(), std::vector<std::string>{kFirst});
  ExpectWholeJpeg(kFirst);
}

TEST_F(CameraDaemonTest, DroppedFrameGetsAFreshBurst) {
  sensor_.AddFault(Fault::kDrop);
  StartDaemon();
  PressAndWait();
  EXPECT_EQ(sink_.Count("photo 1: sensor synthetic frame 2: test: frame 2: 1 frame(s) dropped; "
                        "taking a fresh burst (retry 1 of 1)"),
            1)
      << sink_.All();
  EXPECT_EQ(Files(), std::vector<std::string>{kFirst});
  ExpectWholeJpeg(kFirst);
}

TEST_F(CameraDaemonTest, DroppedFrameWithoutRetriesFailsThePhotoOnly) {
  config_.capture_retries = 0;
  sensor_.AddFault(Fault::kDrop);
  StartDaemon();
  PressAndWait();
  EXPECT_EQ(Files(), std::vector<std::string>{});
  EXPECT_EQ(sink_.Count("photo 1: not saved: sensor synthetic frame 2: test: frame 2: 1 frame(s) "
                        "dropped (the sensor is reopened at the next press)"),
            1)
      << sink_.All();
  PressAndWait();
  // The failed photo did not use up a number.
  EXPECT_EQ(Files(), std::vector<std::string>{kFirst});
  EXPECT_EQ(daemon_->counts().failed, 1);
}

TEST_F(CameraDaemonTest, MissingFolderIsNotReadyUntilItAppears) {
  config_.output_dir = dir_.Path("card");
  StartDaemon();
  EXPECT_FALSE(daemon_->ready());
  EXPECT_EQ(
      sink_.Count("error: output folder " + dir_.Path("card") + ": no such file or directory"), 1)
      << sink_.All();
  EXPECT_EQ(sink_.Count("ready: sensor"), 0) << sink_.All();
  PressAndWait();
  EXPECT_EQ(sink_.Count("warning: press: refused, not ready: output folder " + dir_.Path("card") +
                        ": no such file or directory"),
            1)
      << sink_.All();
  // The card is mounted: the next press checks at once and takes its photo, number 1.
  ASSERT_EQ(mkdir(dir_.Path("card").c_str(), 0755), 0);
  PressAndWait();
  EXPECT_EQ(sink_.Count("info: output folder " + dir_.Path("card") + ": writable now"), 1)
      << sink_.All();
  EXPECT_EQ(sink_.Count("photo 1: saved " + dir_.Path("card/") + kFirst), 1) << sink_.All();
  const CameraDaemon::Counts c = daemon_->counts();
  EXPECT_EQ(c.presses, 2);
  EXPECT_EQ(c.refused, 1);
  EXPECT_EQ(c.failed, 0);
}

TEST_F(CameraDaemonTest, FolderThatIsAFileIsNotReady) {
  config_.output_dir = dir_.Path("card");
  FILE* f = fopen(config_.output_dir.c_str(), "w");
  ASSERT_NE(f, nullptr);
  fclose(f);
  StartDaemon();
  PressAndWait();
  EXPECT_FALSE(daemon_->ready());
  EXPECT_EQ(sink_.Count("press: refused, not ready: output folder " + dir_.Path("card") +
                        ": not a folder (a regular file)"),
            1)
      << sink_.All();
  EXPECT_EQ(sink_.Count("ready: sensor"), 0) << sink_.All();
}

TEST_F(CameraDaemonTest, FolderGoneAfterReadyFailsThePhotoUntilItIsBack) {
  config_.output_dir = dir_.Path("card");
  ASSERT_EQ(mkdir(dir_.Path("card").c_str(), 0755), 0);
  StartDaemon();
  ASSERT_TRUE(daemon_->ready()) << sink_.All();
  ASSERT_EQ(rmdir(dir_.Path("card").c_str()), 0);  // the card was taken out
  PressAndWait();
  EXPECT_EQ(sink_.Count("photo 1: not saved: " + dir_.Path("card/") + kFirst + ": the folder " +
                        dir_.Path("card") + ": no such file or directory"),
            1)
      << sink_.All();
  ASSERT_EQ(mkdir(dir_.Path("card").c_str(), 0755), 0);
  PressAndWait();
  EXPECT_EQ(sink_.Count("photo 2: saved"), 1) << sink_.All();
  // A missing folder is no sensor fault: the sensor stays configured.
  EXPECT_EQ(sensor_.configures.load(), 1);
}

TEST_F(CameraDaemonTest, CameraPluggedInLaterIsFoundAndThenPressesWork) {
  sensor_.present = false;
  StartDaemon();
  EXPECT_FALSE(daemon_->ready());
  EXPECT_EQ(sink_.Count("error: camera test0: no such device"), 1) << sink_.All();
  EXPECT_EQ(sink_.Count("warning: not ready: will check again in 1 s"), 1) << sink_.All();
  EXPECT_EQ(sink_.Count("ready: sensor"), 0) << sink_.All();
  // A half press while not ready leaves the sensor alone; a press is refused, with the reason.
  button_.Push(ButtonEvent::kHalfPress);
  PressAndWait();
  EXPECT_EQ(sink_.Count("warning: press: refused, not ready: camera test0: no such device"), 1)
      << sink_.All();
  EXPECT_EQ(sensor_.configures.load(), 0);
  EXPECT_EQ(Files(), std::vector<std::string>{});
  // Plugged in: the next scheduled check (1 s after the start) finds it.
  sensor_.present = true;
  ASSERT_TRUE(sink_.WaitFor("ready: sensor test")) << sink_.All();
  EXPECT_TRUE(daemon_->ready());
  EXPECT_EQ(sink_.Count("info: sensor test: the camera is there now"), 1) << sink_.All();
  PressAndWait();
  EXPECT_EQ(Files(), std::vector<std::string>{kFirst});
  ExpectWholeJpeg(kFirst);
  EXPECT_EQ(daemon_->counts().refused, 1);
  // Ready means done checking.
  const int probes = sensor_.probes.load();
  PressAndWait();
  EXPECT_EQ(sensor_.probes.load(), probes);
}

// Unplugged after the start: the failed photo sends the daemon back to its checks, so the next
// presses are refused with the reason (not each failed as a capture), until the camera is back.
TEST_F(CameraDaemonTest, CameraUnpluggedAfterReadyIsNotReadyUntilItIsBack) {
  StartDaemon();
  ASSERT_TRUE(daemon_->ready());
  sensor_.present = false;
  sensor_.AddFault(Fault::kTimeout);  // what a vanished device gives a burst in progress
  PressAndWait();
  EXPECT_EQ(Files(), std::vector<std::string>{});
  ASSERT_TRUE(sink_.WaitFor("warning: not ready: will check again in 1 s")) << sink_.All();
  EXPECT_FALSE(daemon_->ready());
  EXPECT_EQ(sink_.Count("error: camera test0: no such device"), 1) << sink_.All();
  const int configures = sensor_.configures.load();
  PressAndWait();
  EXPECT_EQ(sink_.Count("warning: press: refused, not ready: camera test0: no such device"), 1)
      << sink_.All();
  EXPECT_EQ(sensor_.configures.load(), configures) << "a refused press leaves the sensor alone";
  // Plugged in again: found by the next scheduled check, and the next press takes its photo.
  sensor_.present = true;
  ASSERT_TRUE(sink_.WaitFor("info: sensor test: the camera is there now")) << sink_.All();
  ASSERT_TRUE(sink_.WaitFor("ready: sensor test", 2)) << sink_.All();
  EXPECT_TRUE(daemon_->ready());
  PressAndWait();
  EXPECT_EQ(Files(), std::vector<std::string>{kFirst}) << sink_.All();
  ExpectWholeJpeg(kFirst);
}

// A capture that fails with the camera still there: checked at once and ready again, and the
// next press works (as before the checks came back).
TEST_F(CameraDaemonTest, FailedCaptureWithTheCameraThereIsReadyAgainAtOnce) {
  StartDaemon();
  sensor_.AddFault(Fault::kTimeout);
  PressAndWait();
  ASSERT_TRUE(sink_.WaitFor("ready: sensor test", 2)) << sink_.All();
  EXPECT_TRUE(daemon_->ready());
  EXPECT_EQ(sink_.Count("not ready"), 0) << sink_.All();
  PressAndWait();
  EXPECT_EQ(Files(), std::vector<std::string>{kFirst}) << sink_.All();
}

TEST_F(CameraDaemonTest, PressChecksAtOnceAndTakesThePhotoWhenTheCameraIsBack) {
  clock_.Freeze(0);  // no scheduled check ever comes due
  sensor_.present = false;
  StartDaemon();
  EXPECT_EQ(sensor_.probes.load(), 1);
  sensor_.present = true;
  PressAndWait();
  EXPECT_EQ(sensor_.probes.load(), 2);
  EXPECT_EQ(Files(), std::vector<std::string>{kFirst}) << sink_.All();
  EXPECT_EQ(sink_.Count("press: photo 1"), 1) << sink_.All();
  EXPECT_EQ(daemon_->counts().refused, 0);
}

TEST_F(CameraDaemonTest, AbsentCameraIsCheckedWithBackoffAndLoggedOnce) {
  // Two simulated minutes of waiting for a camera that never comes.
  constexpr int64_t kEndNs = 120 * int64_t{1000000000};
  clock_.Freeze(0);
  sensor_.clock = &clock_;
  sensor_.present = false;
  SimulatedButton button(&clock_, kEndNs);
  StartDaemon(&button);
  for (int i = 0; i < 1000 && clock_.MonotonicNs() < kEndNs; ++i) {
    std::this_thread::sleep_for(milliseconds(10));
  }
  ASSERT_EQ(clock_.MonotonicNs(), kEndNs);
  Stop();
  // At 0, 1, 3, 7, 15, 31, 61 and 91 s: 6 checks in the first minute, 2 a minute after that.
  EXPECT_EQ(sensor_.ProbeGapsMs(),
            (std::vector<int64_t>{1000, 2000, 4000, 8000, 16000, 30000, 30000}));
  EXPECT_EQ(sink_.Count("no such device"), 1) << sink_.All();
  EXPECT_EQ(sink_.Count("not ready"), 1) << sink_.All();
  EXPECT_EQ(sink_.Count("stopped: 0 photo(s) saved"), 1) << sink_.All();
}

TEST_F(CameraDaemonTest, ChangedProblemIsLoggedAndLookedAtSoonAgain) {
  clock_.Freeze(0);
  sensor_.clock = &clock_;
  sensor_.present = false;
  config_.output_dir = dir_.Path("card");
  StartDaemon();
  EXPECT_EQ(sink_.Count("error: camera test0: no such device"), 1) << sink_.All();
  EXPECT_EQ(sink_.Count("error: output folder"), 1) << sink_.All();
  // Until the n-th check has been made and the daemon waits again: the clock is moved, or the
  // camera brought, only then, or the check would see them (as a slow machine once showed).
  auto wait_probes = [this](int n) {
    for (int i = 0; i < 1000 && sensor_.probes.load() < n; ++i) {
      std::this_thread::sleep_for(milliseconds(10));
    }
    const int waits = button_.waits.load();
    for (int i = 0; i < 1000 && button_.waits.load() == waits; ++i) {
      std::this_thread::sleep_for(milliseconds(10));
    }
    return sensor_.probes.load() == n && button_.waits.load() > waits;
  };
  // Checks at 1 and 3 s find the same; the camera appears before the one at 7 s.
  clock_.Advance(1000000000);
  ASSERT_TRUE(wait_probes(2));
  clock_.Advance(2000000000);
  ASSERT_TRUE(wait_probes(3));
  EXPECT_EQ(sink_.Count("error: camera test0: no such device"), 1) << sink_.All();
  sensor_.present = true;
  clock_.Advance(4000000000);
  ASSERT_TRUE(sink_.WaitFor("sensor test: the camera is there now")) << sink_.All();
  // Still not ready (no folder), and the next check 1 s later, not 8 s (logged just after the
  // line above: waited for, not counted at once).
  EXPECT_TRUE(sink_.WaitFor("not ready: will check again in 1 s", 2)) << sink_.All();
  EXPECT_FALSE(daemon_->ready());
  EXPECT_EQ(sink_.Count("not ready: will check again in 1 s"), 2) << sink_.All();
  ASSERT_EQ(mkdir(dir_.Path("card").c_str(), 0755), 0);
  clock_.Advance(1000000000);
  ASSERT_TRUE(sink_.WaitFor("ready: sensor test")) << sink_.All();
  EXPECT_EQ(sensor_.ProbeGapsMs(), (std::vector<int64_t>{1000, 2000, 4000, 1000}));
}

TEST_F(CameraDaemonTest, FailedWriteLeavesNothingUnderTheName) {
  // The medium refuses the bytes (a file size limit here; a full card in the VM scenario).
  signal(SIGXFSZ, SIG_IGN);
  rlimit old;
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  rlimit small = old;
  small.rlim_cur = 512;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  StartDaemon();
  PressAndWait();
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &old), 0);
  EXPECT_EQ(Files(), std::vector<std::string>{});
  EXPECT_EQ(sink_.Count("error: photo 1: not saved: " + dir_.Path(kFirst) + ": file too large"), 1)
      << sink_.All();
  PressAndWait();
  EXPECT_EQ(Files(), std::vector<std::string>{kFirst});
  ExpectWholeJpeg(kFirst);
}

TEST_F(CameraDaemonTest, StopFinishesThePhotoInProgressAndDropsTheQueuedPress) {
  StartDaemon();
  sensor_.SetOpen(false);
  button_.Push(ButtonEvent::kPress);
  ASSERT_TRUE(sensor_.WaitBursts(1));
  button_.Push(ButtonEvent::kPress);
  ASSERT_TRUE(sink_.WaitFor("queued")) << sink_.All();
  daemon_->RequestStop();
  ASSERT_TRUE(sink_.WaitFor("stopping: queued press dropped")) << sink_.All();
  sensor_.SetOpen(true);
  runner_.join();
  EXPECT_TRUE(run_status_.ok());
  EXPECT_EQ(Files(), std::vector<std::string>{kFirst});
  ExpectWholeJpeg(kFirst);
  EXPECT_EQ(sink_.Count("stopping: finishing photo 1 first"), 1) << sink_.All();
  EXPECT_GE(sensor_.stops.load(), 1);
}

TEST_F(CameraDaemonTest, ButtonFailureEndsRunWithTheError) {
  StartDaemon();
  button_.Break();
  runner_.join();
  EXPECT_EQ(run_status_.code(), Code::kNotFound);
  EXPECT_EQ(sink_.Count("error: button: test button: the input device went away"), 1)
      << sink_.All();
}

TEST_F(CameraDaemonTest, StartClearsTemporariesAndContinuesTheCount) {
  FILE* f = fopen(dir_.Path(".IMG_20260101_120000_0007.jpg.AbCdEf").c_str(), "w");
  ASSERT_NE(f, nullptr);
  fclose(f);
  f = fopen(dir_.Path("IMG_20260101_120000_0006.jpg").c_str(), "w");
  ASSERT_NE(f, nullptr);
  fclose(f);
  StartDaemon();
  EXPECT_EQ(sink_.Count("output: removed 1 unfinished photo(s)"), 1) << sink_.All();
  PressAndWait();
  EXPECT_EQ(Files(), (std::vector<std::string>{"IMG_20260101_120000_0006.jpg",
                                               "IMG_20260314_150926_0007.jpg"}));
}

}  // namespace
}  // namespace lb
