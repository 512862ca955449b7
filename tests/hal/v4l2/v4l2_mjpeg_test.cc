// The V4L2 sensor on an MJPEG camera: when it takes MJPEG, what the sink receives, and what a
// corrupt frame does to a burst.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "hal/v4l2/v4l2_sensor.h"
#include "tests/hal/v4l2/fake_v4l2.h"
#include "tests/hal/v4l2/jpeg_frames.h"

namespace lb {
namespace {

using jpegtest::Rgb;

// Whole frames put together from the strips.
class FramesSink : public FrameSink {
 public:
  std::vector<FrameInfo> infos;
  std::vector<Rgb> frames;
  int ended = 0, max_strip = 0, bad_strips = 0;

  Status BeginFrame(const FrameInfo& info) override {
    infos.push_back(info);
    frames.emplace_back();
    frames.back().width = info.width;
    frames.back().height = info.height;
    frames.back().pixels.assign(size_t(info.width) * info.height * 3, 0);
    next_ = 0;
    return Status::Ok();
  }
  Status Rows(const FrameRows& rows) override {
    Rgb& f = frames.back();
    if (rows.y0 != next_ || rows.y0 + rows.height > f.height) ++bad_strips;
    if (rows.height > max_strip) max_strip = rows.height;
    for (int32_t y = 0; y < rows.height && rows.y0 + y < f.height; ++y) {
      memcpy(&f.pixels[size_t(rows.y0 + y) * f.width * 3], rows.planes[0] + rows.strides[0] * y,
             size_t(f.width) * 3);
    }
    next_ = rows.y0 + rows.height;
    return Status::Ok();
  }
  Status EndFrame() override {
    ++ended;
    return Status::Ok();
  }

 private:
  int32_t next_ = 0;
};

struct Lines {
  std::vector<std::string> lines;
  static void Write(void* context, const char* line) {
    static_cast<Lines*>(context)->lines.push_back(line);
  }
};

bool Contains(const std::string& text, const char* part) {
  return text.find(part) != std::string::npos;
}

int MaxDifference(const Rgb& a, const Rgb& b) {
  if (a.pixels.size() != b.pixels.size()) return 999;
  int m = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    m = std::max(m, std::abs(int(a.pixels[i]) - int(b.pixels[i])));
  }
  return m;
}

SensorConfig Burst(int frames, int32_t width = 0, int32_t height = 0) {
  SensorConfig c;
  c.frames = frames;
  c.timeout_ms = 50;
  c.width = width;
  c.height = height;
  return c;
}

// A camera like most USB ones: YUYV only at the small sizes, MJPEG up to the large one.
void UsbCamera(FakeV4l2* dev) {
  dev->formats = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG};
  dev->sizes = {{V4L2_PIX_FMT_YUYV, 32, 24},
                {V4L2_PIX_FMT_YUYV, 64, 48},
                {V4L2_PIX_FMT_MJPEG, 64, 48},
                {V4L2_PIX_FMT_MJPEG, 96, 64}};
}

// Frames as the camera sends them (no Huffman tables), each its own picture.
std::vector<std::vector<uint8_t>> CameraFrames(int n, int32_t w, int32_t h,
                                               std::vector<Rgb>* pictures = nullptr) {
  std::vector<std::vector<uint8_t>> frames;
  for (int i = 0; i < n; ++i) {
    Rgb p = jpegtest::TestPicture(w, h, static_cast<uint32_t>(i));
    frames.push_back(jpegtest::WithoutHuffmanTables(jpegtest::Encode(p, {})));
    if (pictures) pictures->push_back(std::move(p));
  }
  return frames;
}

TEST(V4l2MjpegTest, TakesMjpegOnlyWhereNothingUncompressedHasTheSize) {
  FakeV4l2 dev;
  UsbCamera(&dev);
  dev.jpeg_frames = CameraFrames(1, 96, 64);
  V4l2Sensor sensor(V4l2Options{}, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(3, 96, 64), &mode).ok());
  EXPECT_EQ(sensor.fourcc(), V4L2_PIX_FMT_MJPEG);
  EXPECT_TRUE(sensor.layout().compressed);
  EXPECT_EQ(mode.format, PixelFormat::kRgb8);
  EXPECT_EQ(mode.width, 96);
  EXPECT_EQ(mode.height, 64);
  EXPECT_TRUE(sensor.decoder().configured());

  ASSERT_TRUE(sensor.Configure(Burst(3, 64, 48), &mode).ok());
  EXPECT_EQ(sensor.fourcc(), V4L2_PIX_FMT_YUYV);
  EXPECT_EQ(mode.format, PixelFormat::kYuyv);
  EXPECT_FALSE(sensor.decoder().configured());

  // A size nothing offers: uncompressed first, at the size the driver picks.
  ASSERT_TRUE(sensor.Configure(Burst(3, 80, 60), &mode).ok());
  EXPECT_EQ(sensor.fourcc(), V4L2_PIX_FMT_YUYV);
  EXPECT_EQ(mode.width, 64);
}

TEST(V4l2MjpegTest, JpegFourccAndAnExplicitRequestAreTaken) {
  FakeV4l2 dev;
  dev.formats = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_JPEG};
  dev.jpeg_frames = CameraFrames(2, 64, 48);
  V4l2Options options;
  options.fourcc = V4L2_PIX_FMT_JPEG;
  V4l2Sensor sensor(options, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(2), &mode).ok());
  EXPECT_EQ(sensor.fourcc(), V4L2_PIX_FMT_JPEG);
  FramesSink sink;
  Status s = sensor.CaptureBurst(sink);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(sink.ended, 2);
  // Only MJPEG offered: taken without asking.
  sensor.Stop();
  dev.formats = {V4L2_PIX_FMT_MJPEG};
  V4l2Sensor plain(V4l2Options{}, &dev);
  ASSERT_TRUE(plain.Configure(Burst(2), &mode).ok());
  EXPECT_EQ(plain.fourcc(), V4L2_PIX_FMT_MJPEG);
}

TEST(V4l2MjpegTest, BurstArrivesAsRgbStripsOfTheEncodedPictures) {
  FakeV4l2 dev;
  UsbCamera(&dev);
  std::vector<Rgb> pictures;
  dev.jpeg_frames = CameraFrames(5, 96, 64, &pictures);
  V4l2Options options;
  options.buffers = 2;  // requeued through the burst
  V4l2Sensor sensor(options, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(5, 96, 64), &mode).ok());
  FramesSink sink;
  Status s = sensor.CaptureBurst(sink);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(sink.frames.size(), 5u);
  EXPECT_EQ(sink.ended, 5);
  EXPECT_EQ(sink.bad_strips, 0);
  EXPECT_EQ(sink.max_strip, MjpegDecoder::kStripRows);
  EXPECT_EQ(sensor.corrupt_frames(), 0);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(sink.infos[i].index, i);
    EXPECT_EQ(sink.infos[i].sequence, uint32_t(i));
    EXPECT_EQ(sink.infos[i].format, PixelFormat::kRgb8);
    EXPECT_EQ(sink.infos[i].timestamp_ns, (100 + i) * 1000000000LL);
    EXPECT_EQ(MaxDifference(sink.frames[i], jpegtest::DecodeWithLibjpeg(dev.jpeg_frames[i])), 0);
    EXPECT_LT(MaxDifference(sink.frames[i], pictures[i]), 48) << "frame " << i;
  }
  EXPECT_FALSE(dev.streaming);
}

TEST(V4l2MjpegTest, CorruptFramesAreSkippedWithOneLineEachAndTheNextTakesTheirPlace) {
  FakeV4l2 dev;
  std::vector<std::vector<uint8_t>> frames = CameraFrames(6, 64, 48);
  frames[1].resize(frames[1].size() / 2);                              // cut short
  frames[3] = jpegtest::Encode(jpegtest::TestPicture(32, 24, 3), {});  // another size
  frames[4].clear();                                                   // bytesused 0
  dev.formats = {V4L2_PIX_FMT_MJPEG};
  dev.jpeg_frames = frames;
  Lines log;
  V4l2Options options;
  options.log = Lines::Write;
  options.log_context = &log;
  V4l2Sensor sensor(options, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(3), &mode).ok());
  FramesSink sink;
  Status s = sensor.CaptureBurst(sink);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(sink.infos.size(), 3u);
  EXPECT_EQ(sink.infos[0].sequence, 0u);
  EXPECT_EQ(sink.infos[1].sequence, 2u);
  EXPECT_EQ(sink.infos[2].sequence, 5u);
  EXPECT_EQ(sink.infos[2].index, 2);
  EXPECT_EQ(MaxDifference(sink.frames[2], jpegtest::DecodeWithLibjpeg(frames[5])), 0);
  EXPECT_EQ(sensor.corrupt_frames(), 3);
  ASSERT_EQ(log.lines.size(), 3u);
  EXPECT_EQ(log.lines[0],
            "/dev/video0: corrupt MJPEG frame (sequence 1) skipped, 1 of at most 3 this burst: "
            "truncated: the data ends inside the scan, with no end marker, after " +
                std::to_string(frames[1].size()) + " bytes");
  EXPECT_TRUE(Contains(log.lines[1],
                       "(sequence 3) skipped, 2 of at most 3 this burst: the frame "
                       "header says 32x24, the mode is 64x48"))
      << log.lines[1];
  EXPECT_TRUE(Contains(log.lines[2],
                       "(sequence 4) skipped, 3 of at most 3 this burst: empty "
                       "frame (0 bytes)"))
      << log.lines[2];
}

TEST(V4l2MjpegTest, ARunOfCorruptFramesFailsTheBurstAndTheNextBurstWorks) {
  FakeV4l2 dev;
  dev.formats = {V4L2_PIX_FMT_MJPEG};
  const std::vector<std::vector<uint8_t>> good = CameraFrames(3, 64, 48);
  std::vector<uint8_t> garbage(2000, 0x5A);
  dev.jpeg_frames = {good[0], garbage, garbage, garbage, garbage, good[1]};
  V4l2Sensor sensor(V4l2Options{}, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(3), &mode).ok());
  FramesSink sink;
  Status s = sensor.CaptureBurst(sink);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_STREQ(s.message(),
               "/dev/video0: 4 corrupt MJPEG frames in this burst, at most 3 skipped; burst "
               "abandoned; the last (sequence 4): no JPEG start marker (the frame begins 5a 5a)");
  EXPECT_EQ(sink.infos.size(), 1u);
  EXPECT_FALSE(dev.streaming);

  dev.jpeg_frames = good;
  FramesSink again;
  s = sensor.CaptureBurst(again);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(again.ended, 3);
  EXPECT_EQ(sensor.corrupt_frames(), 0);

  // None allowed: the first corrupt frame ends the burst.
  sensor.Stop();
  V4l2Options strict;
  strict.max_corrupt_frames = 0;
  dev.jpeg_frames = {good[0], garbage};
  V4l2Sensor sensor0(strict, &dev);
  ASSERT_TRUE(sensor0.Configure(Burst(3), &mode).ok());
  FramesSink third;
  EXPECT_EQ(sensor0.CaptureBurst(third).code(), Code::kCorruptData);
  strict.max_corrupt_frames = 65;
  V4l2Sensor too_many(strict, &dev);
  EXPECT_EQ(too_many.Configure(Burst(3), &mode).code(), Code::kInvalidArgument);
}

TEST(V4l2MjpegTest, DamageFoundAfterRowsWentToTheSinkFailsTheBurst) {
  FakeV4l2 dev;
  dev.formats = {V4L2_PIX_FMT_MJPEG};
  std::vector<std::vector<uint8_t>> frames = CameraFrames(3, 64, 48);
  const size_t scan = jpegtest::ScanStart(frames[1]);
  frames[1].resize(scan + (frames[1].size() - scan) / 3);
  frames[1].push_back(0xFF);
  frames[1].push_back(0xD9);
  dev.jpeg_frames = frames;
  Lines log;
  V4l2Options options;
  options.log = Lines::Write;
  options.log_context = &log;
  V4l2Sensor sensor(options, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(3), &mode).ok());
  FramesSink sink;
  Status s = sensor.CaptureBurst(sink);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_TRUE(Contains(s.message(), "/dev/video0: frame 1 (sequence 1): corrupt after "))
      << s.message();
  EXPECT_TRUE(Contains(s.message(), "premature end of data segment")) << s.message();
  EXPECT_EQ(sink.infos.size(), 2u);
  EXPECT_EQ(sink.ended, 1);
  EXPECT_TRUE(log.lines.empty());
  EXPECT_FALSE(dev.streaming);
}

}  // namespace
}  // namespace lb
