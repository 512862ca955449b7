// libcamera sensor, built against libcamera 0.0.3 (Debian 12) to 0.7 (libcamera_version.h
// picks the code paths): one StillCapture stream, buffers from a FrameBufferAllocator mapped
// once at Configure (buffer_layout.h), one request per buffer reused across the burst. Where the
// camera lists the controls, exposure, gain and white balance are metered on one frame and then
// held for the whole burst (exposure_hold.h); what it cannot hold is told to the owner
// (LibcameraOptions::log). Every frame reaches the sink as one strip straight from its mapped
// buffer. Startup frames are skipped; a gap in the frame sequence numbers after them or a frame the
// pipeline handler marks failed abandons the burst, as in the V4L2 sensor (frame_check.h).
//
// libcamera allows one CameraManager per process: a process holds one LibcameraSensor at a time.
#pragma once

#include <cstdint>
#include <memory>

#include "hal/sensor.h"

namespace lb {

struct LibcameraOptions {
  const char* camera_id = "";  // empty: the first camera the manager lists; copied
  bool hold_exposure = true;   // meter one frame, then fix exposure, gain and white balance
  // Told what the burst cannot hold constant: one line, no newline, e.g. "libcamera ID: cannot
  // hold white balance (no AwbEnable control) across the burst: it may drift from frame to
  // frame", once per configuration and again when it changes, on the capturing thread.
  // nullptr: not told (exposure_held() and the others still say).
  void (*log)(void* context, const char* line) = nullptr;
  void* log_context = nullptr;
};

class LibcameraSensor : public Sensor {
 public:
  explicit LibcameraSensor(const LibcameraOptions& options);
  ~LibcameraSensor() override;
  LibcameraSensor(const LibcameraSensor&) = delete;
  LibcameraSensor& operator=(const LibcameraSensor&) = delete;

  const char* name() const override { return "libcamera"; }
  // Starts the camera manager (kept for Configure) and looks for the configured camera, or any
  // when none is named: kNotFound "libcamera: no camera found" or "libcamera: no camera 'X'
  // (found: a, b)". Does not acquire the camera. A camera plugged in later shows up through
  // libcamera's hotplug handling, which, like libcamera's device enumeration itself, needs udev.
  Status Probe() override;
  Status Configure(const SensorConfig& config, SensorMode* mode) override;
  Status CaptureBurst(FrameSink& sink) override;
  void Stop() override;

  // What the last burst held constant (false where the camera has no such controls).
  bool exposure_held() const;
  bool gain_held() const;
  bool white_balance_held() const;
  // The id of the configured camera ("" before Configure).
  const char* camera_id() const;

 private:
  struct Impl;  // keeps libcamera's headers out of this interface
  std::unique_ptr<Impl> impl_;
};

}  // namespace lb
