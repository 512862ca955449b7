// The shutter button: a source of half-press and full-press events, whatever drives it (an evdev
// gpio-keys device on the board, a simulated button on the host).
#pragma once

#include <cstdint>

#include "algo/core/status.h"

namespace lb {

enum class ButtonEvent : uint8_t {
  kNone,       // the wait timed out
  kHalfPress,  // KEY_CAMERA_FOCUS down: wake the sensor
  kPress,      // KEY_CAMERA down: take the burst
  kRelease,    // KEY_CAMERA up
};

class Button {
 public:
  virtual ~Button() = default;
  // Waits up to `timeout_ms` (-1 = forever) for the next event; kNone on timeout. Key repeat and
  // contact bounce are filtered out by the implementation.
  virtual Status Wait(int32_t timeout_ms, ButtonEvent* event) = 0;
};

}  // namespace lb
