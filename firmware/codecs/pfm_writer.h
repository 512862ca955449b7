// The product's PFM writer (portable float map, Middlebury's disparity format): one channel
// ("Pf"), little-endian (scale -1.0), rows stored bottom to top.
#pragma once

#include <cstdint>
#include <vector>

#include "algo/core/status.h"
#include "firmware/storage/atomic_file.h"

namespace lb {

class PfmWriter {
 public:
  // Writes the header of a width x height map into `out` (borrowed until the last row).
  Status Begin(AtomicFile* out, int32_t width, int32_t height);
  // The next row in the file's order: the image's bottom row first. `values` holds width floats.
  Status WriteRow(const float* values);

 private:
  AtomicFile* out_ = nullptr;
  int32_t width_ = 0;
  int32_t rows_left_ = 0;
  std::vector<uint8_t> row_;  // one row's bytes, sized by Begin
};

}  // namespace lb
