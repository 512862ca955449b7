#include "sim/synthetic/synthetic_sensor.h"

namespace lb {

Status SyntheticSensor::Configure(const SensorConfig& config, SensorMode* mode) {
  configured_ = false;
  const int32_t width = config.width == 0 ? kDefaultWidth : config.width;
  const int32_t height = config.height == 0 ? kDefaultHeight : config.height;
  const int32_t frames = config.frames == 0 ? kDefaultFrames : config.frames;
  Status status = scene_.Configure(params_, width, height, frames);
  if (!status.ok()) return status.Prefix("sensor %s: ", name());
  mode_ = SensorMode{width, height, PixelFormat::kRgb8, frames, scene_.intrinsics().fx};
  strip_.assign(static_cast<size_t>(width) * 3 * kStripRows, 0);
  if (mode != nullptr) *mode = mode_;
  configured_ = true;
  return Status::Ok();
}

Status SyntheticSensor::CaptureBurst(FrameSink& sink) {
  if (!configured_)
    return Status(Code::kInvalidArgument, "sensor %s: CaptureBurst before Configure", name());
  const ptrdiff_t stride = ptrdiff_t{mode_.width} * 3;
  for (int32_t i = 0; i < mode_.frames; ++i) {
    FrameInfo info;
    info.index = i;
    info.format = PixelFormat::kRgb8;
    info.width = mode_.width;
    info.height = mode_.height;
    info.timestamp_ns = i * kFrameIntervalNs;
    info.sequence = sequence_++;
    Status status = sink.BeginFrame(info);
    for (int32_t y0 = 0; status.ok() && y0 < mode_.height; y0 += kStripRows) {
      const int32_t rows = mode_.height - y0 < kStripRows ? mode_.height - y0 : kStripRows;
      status = scene_.RenderRows(i, y0, rows, strip_.data(), stride);
      if (!status.ok()) break;
      FrameRows strip;
      strip.y0 = y0;
      strip.height = rows;
      strip.planes[0] = strip_.data();
      strip.strides[0] = stride;
      status = sink.Rows(strip);
    }
    if (status.ok()) status = sink.EndFrame();
    if (!status.ok()) return status.Prefix("sensor %s frame %d: ", name(), i);
  }
  return Status::Ok();
}

}  // namespace lb
