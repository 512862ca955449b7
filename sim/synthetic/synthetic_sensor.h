// The synthetic scene as a Sensor: the product's default input on a PC, where a clone carries no
// photos. Delivers RGB8 frames in strips of kStripRows rows; frame i has index i, timestamp
// i * 33 ms and the next sequence number. The scene stays reachable for ground truth.
#pragma once

#include <cstdint>
#include <vector>

#include "hal/sensor.h"
#include "sim/synthetic/scene.h"

namespace lb {

class SyntheticSensor : public Sensor {
 public:
  static constexpr int32_t kDefaultWidth = 1280;
  static constexpr int32_t kDefaultHeight = 960;
  static constexpr int32_t kDefaultFrames = 5;
  static constexpr int32_t kStripRows = 16;
  static constexpr int64_t kFrameIntervalNs = 33'000'000;

  explicit SyntheticSensor(const SceneParams& params = SceneParams()) : params_(params) {}

  const char* name() const override { return "synthetic"; }
  // width/height 0 pick 1280x960, frames 0 picks 5. Allocates the scene and one strip.
  Status Configure(const SensorConfig& config, SensorMode* mode) override;
  Status CaptureBurst(FrameSink& sink) override;
  void Stop() override { configured_ = false; }

  // Takes effect at the next Configure.
  void set_params(const SceneParams& params) { params_ = params; }
  const Scene& scene() const { return scene_; }
  Scene& scene() { return scene_; }

 private:
  SceneParams params_;
  Scene scene_;
  SensorMode mode_;
  bool configured_ = false;
  uint32_t sequence_ = 0;
  std::vector<uint8_t> strip_;
};

}  // namespace lb
