// EvdevButton: the shutter button as a Linux input device (gpio-keys on the board, uinput in the
// VM test). KEY_CAMERA down is a press, KEY_CAMERA_FOCUS down a half press. Autorepeat (value 2)
// is ignored, and so is contact bounce: a key-down counts only when the key has been quiet for
// the debounce window (kernel event times), so chatter never yields a second press while a
// clean press is reported at once. Events the kernel dropped (SYN_DROPPED) are resynchronised
// from the device's key state, so a press hidden in the overflow is still reported.
#pragma once

#include <linux/input.h>

#include <cstddef>
#include <cstdint>

#include "hal/button.h"

namespace lb {

class EvdevButton : public Button {
 public:
  static constexpr int32_t kDefaultDebounceMs = 30;

  explicit EvdevButton(int32_t debounce_ms = kDefaultDebounceMs) : debounce_ms_(debounce_ms) {}
  ~EvdevButton() override { Close(); }
  EvdevButton(const EvdevButton&) = delete;
  EvdevButton& operator=(const EvdevButton&) = delete;

  // Opens /dev/input/eventN and checks it can send KEY_CAMERA.
  Status Open(const char* path);
  // Takes ownership of an already open descriptor delivering struct input_event records (tests
  // feed a pipe); `name` is for messages.
  void Adopt(int fd, const char* name);
  void Close();

  Status Wait(int32_t timeout_ms, ButtonEvent* event) override;

  // Scans /dev/input/event0..63 for the first device that can send KEY_CAMERA.
  static Status FindCameraButton(char* path, size_t size);

 private:
  struct Key {
    bool down = false;
    bool seen = false;    // any transition yet
    int64_t last_us = 0;  // kernel time of the last transition, accepted or not
  };
  static constexpr int kMaxPending = 64;
  static constexpr int kReadEvents = 16;  // <= kMaxPending: a read can never overflow the queue

  void Feed(const input_event& ev);
  void Resync(int64_t now_us);
  void OnKey(Key& key, bool down, int64_t now_us, ButtonEvent press, bool report_release);
  void Push(ButtonEvent event);

  int fd_ = -1;
  char name_[128] = {};
  int32_t debounce_ms_;
  Key camera_, focus_;
  bool dropping_ = false;  // between SYN_DROPPED and the next SYN_REPORT
  uint8_t partial_[sizeof(input_event)] = {};
  size_t partial_bytes_ = 0;
  ButtonEvent pending_[kMaxPending] = {};
  int head_ = 0, count_ = 0;
};

}  // namespace lb
