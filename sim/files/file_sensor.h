// A sensor that "captures" a burst from image files on the host: frame i is the i-th file.
// Frames must all have the same size and the same decoded pixel format; a folder mixing grey
// and colour files (Middlebury's truedisp.pgm next to the views) is rejected rather than
// silently converted, because a stray file in the burst is almost always a mistake.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "algo/core/status.h"
#include "hal/image_decoder.h"
#include "hal/sensor.h"

namespace lb {

class FileSensor : public Sensor {
 public:
  // The image files in `dir` (.ppm .pgm .pnm .png .jpg .jpeg in any case, sorted by name); the
  // folder is listed and every file probed by Configure. `decoder` reads them; it is borrowed
  // for the sensor's life.
  static Status FromDirectory(const char* dir, const ImageDecoder& decoder,
                              std::unique_ptr<FileSensor>* out);
  // These files in this order.
  static Status FromFiles(const std::vector<std::string>& paths, const ImageDecoder& decoder,
                          std::unique_ptr<FileSensor>* out);

  // Frames outside min_side x min_side .. max_width x max_height are refused by Configure, with
  // a message naming the first file (by default any size the decoder reads is taken).
  void LimitSize(int32_t min_side, int32_t max_width, int32_t max_height);

  const char* name() const override { return "file"; }
  // Reads every file's header. A non-zero config.width/height must match the files (no
  // scaling); config.frames is ignored: the burst is as long as the file list.
  Status Configure(const SensorConfig& config, SensorMode* mode) override;
  // Streams file i as frame i, timestamp i * 33 ms, sequence i.
  Status CaptureBurst(FrameSink& sink) override;
  void Stop() override { configured_ = false; }

  // The files of the configured burst, in frame order.
  const std::vector<std::string>& paths() const { return paths_; }

 private:
  explicit FileSensor(const ImageDecoder& decoder) : decoder_(decoder) {}
  Status ListDirectory();
  Status CheckLimits(const ImageHeader& first) const;

  const ImageDecoder& decoder_;
  int32_t min_side_ = 0;
  int32_t max_width_ = 0;  // 0: no limit
  int32_t max_height_ = 0;

  std::string dir_;  // empty when built from a file list
  std::vector<std::string> paths_;
  SensorMode mode_;
  bool configured_ = false;
};

}  // namespace lb
