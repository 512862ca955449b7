// A FrameSink that keeps what it is given and checks the streaming contract: BeginFrame, strips
// of at most kImageStripRows rows in order covering the frame once, EndFrame.
#pragma once

#include <cstring>
#include <string>
#include <vector>

#include "algo/core/frame.h"
#include "firmware/codecs/image_file.h"

namespace lb::test {

class RecordingSink : public FrameSink {
 public:
  struct Frame {
    FrameInfo info;
    std::vector<uint8_t> pixels;
    std::vector<int32_t> strip_heights;
    bool ended = false;
  };

  Status BeginFrame(const FrameInfo& info) override {
    if (!frames.empty() && !frames.back().ended) return Fail("BeginFrame before EndFrame");
    frames.push_back(Frame{info, {}, {}, false});
    next_row_ = 0;
    return Status::Ok();
  }
  Status Rows(const FrameRows& rows) override {
    if (frames.empty() || frames.back().ended) return Fail("Rows outside a frame");
    Frame& f = frames.back();
    if (rows.y0 != next_row_) return Fail("rows out of order");
    if (rows.height < 1 || rows.height > kImageStripRows) return Fail("bad strip height");
    if (rows.y0 + rows.height > f.info.height) return Fail("rows past the frame");
    const size_t row_bytes =
        static_cast<size_t>(f.info.width) * static_cast<size_t>(BytesPerPixel(f.info.format));
    for (int32_t y = 0; y < rows.height; ++y) {
      const uint8_t* row = rows.planes[0] + y * rows.strides[0];
      f.pixels.insert(f.pixels.end(), row, row + row_bytes);
    }
    f.strip_heights.push_back(rows.height);
    next_row_ += rows.height;
    return Status::Ok();
  }
  Status EndFrame() override {
    if (frames.empty() || frames.back().ended) return Fail("EndFrame outside a frame");
    if (next_row_ != frames.back().info.height) return Fail("EndFrame before the last row");
    frames.back().ended = true;
    return Status::Ok();
  }

  std::vector<Frame> frames;
  std::string error;  // the first broken contract, if any

 private:
  Status Fail(const char* what) {
    if (error.empty()) error = what;
    return Status(Code::kInternal, "recording sink: %s", what);
  }
  int32_t next_row_ = 0;
};

// Reads a 16-bit native sample.
inline uint16_t Sample16(const std::vector<uint8_t>& pixels, size_t i) {
  uint16_t v = 0;
  memcpy(&v, pixels.data() + 2 * i, 2);
  return v;
}

}  // namespace lb::test
