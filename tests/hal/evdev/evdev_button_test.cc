// The button fed through a pipe with the records an evdev device would deliver.
#include "hal/evdev/evdev_button.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <time.h>
#include <unistd.h>

#include <string>
#include <vector>

namespace lb {
namespace {

class EvdevButtonTest : public ::testing::Test {
 protected:
  void SetUp() override {
    int fds[2];
    ASSERT_EQ(pipe2(fds, O_CLOEXEC), 0);
    button_.Adopt(fds[0], "test-pipe");
    writer_ = fds[1];
  }
  void TearDown() override {
    if (writer_ >= 0) close(writer_);
  }

  // One event at `ms` milliseconds of kernel time, followed by its SYN_REPORT.
  void Key(int code, int value, int64_t ms) {
    Send(EV_KEY, code, value, ms);
    Send(EV_SYN, SYN_REPORT, 0, ms);
  }
  void Send(int type, int code, int value, int64_t ms) {
    input_event ev = {};
    ev.input_event_sec = static_cast<decltype(ev.input_event_sec)>(ms / 1000);
    ev.input_event_usec = static_cast<decltype(ev.input_event_usec)>((ms % 1000) * 1000);
    ev.type = static_cast<uint16_t>(type);
    ev.code = static_cast<uint16_t>(code);
    ev.value = value;
    ASSERT_EQ(write(writer_, &ev, sizeof(ev)), static_cast<ssize_t>(sizeof(ev)));
  }
  // Every event available now (the pipe is drained with short timeouts).
  std::vector<ButtonEvent> Drain() {
    std::vector<ButtonEvent> events;
    for (;;) {
      ButtonEvent e;
      Status s = button_.Wait(20, &e);
      EXPECT_TRUE(s.ok()) << s.message();
      if (!s.ok() || e == ButtonEvent::kNone) return events;
      events.push_back(e);
    }
  }

  EvdevButton button_{30};
  int writer_ = -1;
};

using E = ButtonEvent;

TEST_F(EvdevButtonTest, PressAndRelease) {
  Key(KEY_CAMERA, 1, 1000);
  Key(KEY_CAMERA, 0, 1200);
  EXPECT_EQ(Drain(), (std::vector<E>{E::kPress, E::kRelease}));
}

TEST_F(EvdevButtonTest, AutorepeatIsIgnored) {
  Key(KEY_CAMERA, 1, 1000);
  for (int i = 1; i <= 10; ++i) Key(KEY_CAMERA, 2, 1000 + 250 + 33 * i);
  Key(KEY_CAMERA, 0, 2000);
  EXPECT_EQ(Drain(), (std::vector<E>{E::kPress, E::kRelease}));
}

TEST_F(EvdevButtonTest, BounceGivesOnePressAndTheNextRealPressCounts) {
  // Contacts chattering for 8 ms on the way down and on the way up.
  Key(KEY_CAMERA, 1, 1000);
  Key(KEY_CAMERA, 0, 1002);
  Key(KEY_CAMERA, 1, 1004);
  Key(KEY_CAMERA, 0, 1006);
  Key(KEY_CAMERA, 1, 1008);
  Key(KEY_CAMERA, 0, 1300);
  Key(KEY_CAMERA, 1, 1303);
  Key(KEY_CAMERA, 0, 1306);
  EXPECT_EQ(Drain(), (std::vector<E>{E::kPress, E::kRelease}));
  // A deliberate second press half a second later.
  Key(KEY_CAMERA, 1, 1800);
  Key(KEY_CAMERA, 0, 1900);
  EXPECT_EQ(Drain(), (std::vector<E>{E::kPress, E::kRelease}));
}

TEST_F(EvdevButtonTest, QuickTapsOutsideTheWindowAllCount) {
  for (int i = 0; i < 5; ++i) {
    Key(KEY_CAMERA, 1, 1000 + 100 * i);
    Key(KEY_CAMERA, 0, 1000 + 100 * i + 40);
  }
  std::vector<E> events = Drain();
  EXPECT_EQ(std::count(events.begin(), events.end(), E::kPress), 5);
}

TEST_F(EvdevButtonTest, HalfPressThenFullPress) {
  Key(KEY_CAMERA_FOCUS, 1, 1000);
  Key(KEY_CAMERA, 1, 1400);
  Key(KEY_CAMERA, 0, 1500);
  Key(KEY_CAMERA_FOCUS, 0, 1510);
  EXPECT_EQ(Drain(), (std::vector<E>{E::kHalfPress, E::kPress, E::kRelease}));
}

TEST_F(EvdevButtonTest, OtherKeysAndEventTypesAreIgnored) {
  Send(EV_MSC, MSC_SCAN, 0x90001, 1000);
  Key(KEY_A, 1, 1000);
  Key(KEY_VOLUMEUP, 1, 1001);
  Send(EV_ABS, ABS_X, 10, 1002);
  Send(EV_SYN, SYN_REPORT, 0, 1002);
  EXPECT_TRUE(Drain().empty());
}

TEST_F(EvdevButtonTest, EventsInsideAnOverflowAreDiscarded) {
  // Without a real device there is no key state to resync from; what matters is that the
  // half-reported packet is not taken as input.
  Send(EV_SYN, SYN_DROPPED, 0, 1000);
  Key(KEY_CAMERA, 1, 1001);
  Key(KEY_CAMERA, 1, 1500);
  EXPECT_EQ(Drain(), (std::vector<E>{E::kPress}));
}

TEST_F(EvdevButtonTest, ManyEventsInOneReadArriveInOrder) {
  for (int i = 0; i < 40; ++i) {
    Key(KEY_CAMERA, 1, 1000 + 200 * i);
    Key(KEY_CAMERA, 0, 1100 + 200 * i);
  }
  std::vector<E> events = Drain();
  ASSERT_EQ(events.size(), 80u);
  for (size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i], i % 2 ? E::kRelease : E::kPress) << i;
  }
}

TEST_F(EvdevButtonTest, RecordSplitAcrossReadsIsReassembled) {
  input_event ev = {};
  ev.input_event_sec = 5;
  ev.type = EV_KEY;
  ev.code = KEY_CAMERA;
  ev.value = 1;
  const char* bytes = reinterpret_cast<const char*>(&ev);
  ASSERT_EQ(write(writer_, bytes, 5), 5);
  ButtonEvent e;
  ASSERT_TRUE(button_.Wait(20, &e).ok());
  EXPECT_EQ(e, E::kNone);
  ASSERT_EQ(write(writer_, bytes + 5, sizeof(ev) - 5), static_cast<ssize_t>(sizeof(ev) - 5));
  ASSERT_TRUE(button_.Wait(1000, &e).ok());
  EXPECT_EQ(e, E::kPress);
}

TEST_F(EvdevButtonTest, TimeoutReturnsNoneAfterTheWait) {
  timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  ButtonEvent e = E::kPress;
  ASSERT_TRUE(button_.Wait(100, &e).ok());
  clock_gettime(CLOCK_MONOTONIC, &t1);
  EXPECT_EQ(e, E::kNone);
  int64_t ms = (t1.tv_sec - t0.tv_sec) * 1000 + (t1.tv_nsec - t0.tv_nsec) / 1000000;
  EXPECT_GE(ms, 95);
  EXPECT_LT(ms, 2000);
}

TEST_F(EvdevButtonTest, DeviceGoingAwayIsAnError) {
  close(writer_);
  writer_ = -1;
  ButtonEvent e;
  Status s = button_.Wait(1000, &e);
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_NE(std::string(s.message()).find("test-pipe"), std::string::npos) << s.message();
}

TEST(EvdevButtonOpenTest, MissingAndWrongDevicesAreReported) {
  EvdevButton button;
  Status s = button.Open("/nonexistent/event0");
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_NE(std::string(s.message()).find("/nonexistent/event0"), std::string::npos);
  s = button.Open("/dev/null");
  EXPECT_EQ(s.code(), Code::kUnsupported);
  EXPECT_NE(std::string(s.message()).find("not an input device"), std::string::npos) << s.message();
  ButtonEvent e;
  EXPECT_EQ(button.Wait(0, &e).code(), Code::kInvalidArgument);
}

}  // namespace
}  // namespace lb
