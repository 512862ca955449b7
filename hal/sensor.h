// The sensor interface: every image source (the V4L2 and libcamera backends on the board, the
// file-backed and synthetic sensors in sim/) delivers a burst through it, frame by frame and strip
// by strip, into a FrameSink (the pipeline). A strip is valid only during the call receiving it.
#pragma once

#include <cstdint>

#include "algo/core/frame.h"
#include "algo/core/status.h"

namespace lb {

struct SensorConfig {
  int32_t width = 0;  // 0 = the sensor's native size
  int32_t height = 0;
  int32_t frames = 5;         // burst length
  int32_t timeout_ms = 2000;  // a frame that does not arrive in this time fails the burst
};

// What Configure settled on.
struct SensorMode {
  int32_t width = 0;
  int32_t height = 0;
  PixelFormat format = PixelFormat::kRgb8;
  int32_t frames = 0;
  // Focal length in full-resolution px, 0 when the sensor does not know it (the pipeline then
  // assumes a typical compact camera's field of view). Motion estimation needs it.
  double focal_px = 0;
  // EXIF Orientation (1..8) the frames were stored with, 0 when unknown: the photo carries it.
  int32_t orientation = 0;
};

class Sensor {
 public:
  virtual ~Sensor() = default;
  virtual const char* name() const = 0;
  // Checks, without capturing and without keeping the device, that the camera is there and is
  // one this backend can drive (a V4L2 node answers as a streaming capture node, libcamera lists
  // the camera). The daemon runs it before it says "ready" and again while it waits for a camera
  // plugged in later; the message names the device ("camera /dev/video7: no such device").
  // Sources with nothing to look for beforehand (the synthetic scene) keep this default.
  virtual Status Probe() { return Status::Ok(); }
  // Negotiates the mode; may allocate (it runs before the pipeline's no-allocation window).
  virtual Status Configure(const SensorConfig& config, SensorMode* mode) = 0;
  // Captures `mode.frames` frames into `sink`, frame i with FrameInfo::index == i.
  virtual Status CaptureBurst(FrameSink& sink) = 0;
  // Releases the device; Configure may be called again afterwards.
  virtual void Stop() {}
};

}  // namespace lb
