// Runs inside the throw-away VM (tests/vm): a uinput device stands in for the board's gpio-keys
// button, and the events it injects travel through the kernel's real evdev path to EvdevButton.
// Skips (exit 77 semantics via GTEST_SKIP) where /dev/uinput cannot be opened.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/uinput.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "hal/evdev/evdev_button.h"

namespace lb {
namespace {

class UinputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    fd_ = open("/dev/uinput", O_WRONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) {
      if (getenv("LB_REQUIRE_DEVICES")) FAIL() << "no /dev/uinput";
      GTEST_SKIP() << "no /dev/uinput";
    }
    ASSERT_EQ(ioctl(fd_, UI_SET_EVBIT, EV_KEY), 0);
    ASSERT_EQ(ioctl(fd_, UI_SET_KEYBIT, KEY_CAMERA), 0);
    ASSERT_EQ(ioctl(fd_, UI_SET_KEYBIT, KEY_CAMERA_FOCUS), 0);
    uinput_setup setup;
    memset(&setup, 0, sizeof(setup));
    setup.id.bustype = BUS_HOST;
    snprintf(setup.name, sizeof(setup.name), "lb-test-shutter");
    ASSERT_EQ(ioctl(fd_, UI_DEV_SETUP, &setup), 0);
    ASSERT_EQ(ioctl(fd_, UI_DEV_CREATE), 0);
    char sysname[64] = {};
    ASSERT_GE(ioctl(fd_, UI_GET_SYSNAME(sizeof(sysname)), sysname), 0);
    event_path_ = FindEventNode(sysname);
    ASSERT_FALSE(event_path_.empty()) << "no event node under " << sysname;
  }
  void TearDown() override {
    if (fd_ >= 0) {
      ioctl(fd_, UI_DEV_DESTROY);
      close(fd_);
    }
  }

  // /sys/devices/virtual/input/inputN/eventM -> /dev/input/eventM (devtmpfs makes the node).
  static std::string FindEventNode(const char* sysname) {
    for (int i = 0; i < 64; ++i) {
      std::string dir =
          std::string("/sys/devices/virtual/input/") + sysname + "/event" + std::to_string(i);
      if (access(dir.c_str(), F_OK) != 0) continue;
      std::string node = "/dev/input/event" + std::to_string(i);
      for (int wait = 0; wait < 100 && access(node.c_str(), R_OK) != 0; ++wait) usleep(10000);
      return node;
    }
    return "";
  }

  void Emit(int code, int value) {
    input_event ev[2];
    memset(ev, 0, sizeof(ev));
    ev[0].type = EV_KEY;
    ev[0].code = static_cast<uint16_t>(code);
    ev[0].value = value;
    ev[1].type = EV_SYN;
    ev[1].code = SYN_REPORT;
    ASSERT_EQ(write(fd_, ev, sizeof(ev)), static_cast<ssize_t>(sizeof(ev)));
  }

  std::vector<ButtonEvent> Drain(EvdevButton& button) {
    std::vector<ButtonEvent> events;
    for (;;) {
      ButtonEvent e;
      Status s = button.Wait(300, &e);
      EXPECT_TRUE(s.ok()) << s.message();
      if (!s.ok() || e == ButtonEvent::kNone) return events;
      events.push_back(e);
    }
  }

  int fd_ = -1;
  std::string event_path_;
};

using E = ButtonEvent;

TEST_F(UinputTest, KeyCameraPressReachesTheButton) {
  EvdevButton button;
  Status s = button.Open(event_path_.c_str());
  ASSERT_TRUE(s.ok()) << s.message();
  Emit(KEY_CAMERA, 1);
  Emit(KEY_CAMERA, 0);
  EXPECT_EQ(Drain(button), (std::vector<E>{E::kPress, E::kRelease}));
  printf("uinput: %s delivered KEY_CAMERA press and release\n", event_path_.c_str());
}

TEST_F(UinputTest, HalfPressThenPress) {
  EvdevButton button;
  ASSERT_TRUE(button.Open(event_path_.c_str()).ok());
  Emit(KEY_CAMERA_FOCUS, 1);
  usleep(50000);
  Emit(KEY_CAMERA, 1);
  usleep(50000);
  Emit(KEY_CAMERA, 0);
  Emit(KEY_CAMERA_FOCUS, 0);
  EXPECT_EQ(Drain(button), (std::vector<E>{E::kHalfPress, E::kPress, E::kRelease}));
}

TEST_F(UinputTest, RepeatAndBounceGiveOnePress) {
  EvdevButton button(30);
  ASSERT_TRUE(button.Open(event_path_.c_str()).ok());
  // Bounce on the way down (the kernel stamps each event as it is written).
  Emit(KEY_CAMERA, 1);
  Emit(KEY_CAMERA, 0);
  Emit(KEY_CAMERA, 1);
  // Autorepeat while held.
  for (int i = 0; i < 5; ++i) Emit(KEY_CAMERA, 2);
  usleep(100000);
  Emit(KEY_CAMERA, 0);
  std::vector<E> events = Drain(button);
  EXPECT_EQ(std::count(events.begin(), events.end(), E::kPress), 1);
  // A second deliberate press counts.
  usleep(100000);
  Emit(KEY_CAMERA, 1);
  Emit(KEY_CAMERA, 0);
  events = Drain(button);
  EXPECT_EQ(std::count(events.begin(), events.end(), E::kPress), 1);
}

TEST_F(UinputTest, FindCameraButtonFindsIt) {
  char path[64];
  Status s = EvdevButton::FindCameraButton(path, sizeof(path));
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(event_path_, path);
}

TEST_F(UinputTest, UnpluggedDeviceIsReported) {
  EvdevButton button;
  ASSERT_TRUE(button.Open(event_path_.c_str()).ok());
  ASSERT_EQ(ioctl(fd_, UI_DEV_DESTROY), 0);
  close(fd_);
  fd_ = -1;
  ButtonEvent e;
  Status s = button.Wait(2000, &e);
  EXPECT_FALSE(s.ok());
  printf("unplugged: %s\n", s.message());
}

}  // namespace
}  // namespace lb
