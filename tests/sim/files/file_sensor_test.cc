#include "sim/files/file_sensor.h"
#include "firmware/codecs/codec_decoder.h"

#include <libexif/exif-data.h>
#include <png.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tests/firmware/codecs/recording_sink.h"
#include "tests/firmware/codecs/test_images.h"

namespace lb {
namespace {

namespace fs = std::filesystem;
using test::Bytes;

class FileSensorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = ::testing::TempDir() + "file_sensor_" + test->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Path(const std::string& name) const { return dir_ + "/" + name; }

  // A grey or colour PPM/PGM whose every sample is `value`.
  void WritePnm(const std::string& name, int width, int height, int channels, uint16_t value) {
    const std::vector<uint16_t> samples(static_cast<size_t>(width * height * channels), value);
    ASSERT_TRUE(test::WriteFile(
        Path(name), test::EncodePnm(channels == 1 ? "P5" : "P6", width, height, 255, samples)));
  }
  void WritePng(const std::string& name, int width, int height, uint8_t value) {
    test::PngSpec spec{width, height, PNG_COLOR_TYPE_RGB, 8, false, {}, {}};
    spec.rows.assign(static_cast<size_t>(width * height * 3), value);
    Bytes bytes;
    ASSERT_TRUE(test::EncodePng(spec, &bytes));
    ASSERT_TRUE(test::WriteFile(Path(name), bytes));
  }

  Status ConfigureDir(SensorMode* mode) {
    std::unique_ptr<FileSensor> sensor;
    Status s = FileSensor::FromDirectory(dir_.c_str(), CodecImageDecoder(), &sensor);
    if (!s.ok()) return s;
    return sensor->Configure(SensorConfig{}, mode);
  }

  // A JPEG whose EXIF holds FocalLengthIn35mmFilm = f35 (0: a JPEG without EXIF), the block
  // built with libexif and put right after the SOI marker as an APP1 segment.
  void WriteJpeg(const std::string& name, int width, int height, uint16_t f35) {
    std::vector<uint8_t> rgb(static_cast<size_t>(width * height * 3), 128);
    Bytes jpeg;
    ASSERT_TRUE(test::EncodeJpeg(width, height, 3, rgb.data(), 90, false, &jpeg));
    if (f35 > 0) {
      ExifData* data = exif_data_new();
      exif_data_set_byte_order(data, EXIF_BYTE_ORDER_MOTOROLA);
      ExifEntry* e = exif_entry_new();
      exif_content_add_entry(data->ifd[EXIF_IFD_EXIF], e);
      exif_entry_initialize(e, EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM);
      exif_set_short(e->data, EXIF_BYTE_ORDER_MOTOROLA, f35);
      exif_entry_unref(e);
      unsigned char* block = nullptr;
      unsigned int size = 0;
      exif_data_save_data(data, &block, &size);
      exif_data_unref(data);
      ASSERT_NE(block, nullptr);
      const unsigned length = size + 2;
      Bytes app1 = {0xff, 0xe1, static_cast<uint8_t>(length >> 8), static_cast<uint8_t>(length)};
      app1.insert(app1.end(), block, block + size);
      free(block);
      jpeg.insert(jpeg.begin() + 2, app1.begin(), app1.end());
    }
    ASSERT_TRUE(test::WriteFile(Path(name), jpeg));
  }

  std::string dir_;
};

TEST_F(FileSensorTest, FocalLengthComesFromExifWhenTheFilesRecordIt) {
  // 28 mm equivalent on a 640x480 frame: 28 / 43.27 of the 800 px diagonal.
  WriteJpeg("a.jpg", 640, 480, 28);
  WriteJpeg("b.jpg", 640, 480, 28);
  SensorMode mode;
  ASSERT_TRUE(ConfigureDir(&mode).ok());
  EXPECT_NEAR(mode.focal_px, 28.0 * 800.0 / 43.27, 1e-6);

  fs::remove_all(dir_);
  fs::create_directories(dir_);
  WriteJpeg("a.jpg", 640, 480, 0);
  WritePng("b.png", 640, 480, 0);
  ASSERT_TRUE(ConfigureDir(&mode).ok());
  EXPECT_EQ(mode.focal_px, 0.0) << "no EXIF: unknown, not a guess";
}

TEST_F(FileSensorTest, StreamsEveryImageFileInNameOrderWithBurstTiming) {
  WritePnm("c.PPM", 6, 20, 3, 30);
  WritePng("a.png", 6, 20, 10);
  WritePnm("b.pnm", 6, 20, 3, 20);
  ASSERT_TRUE(test::WriteFile(Path("notes.txt"), {'x'}));
  ASSERT_TRUE(test::WriteFile(Path(".hidden.png"), {'x'}));

  std::unique_ptr<FileSensor> sensor;
  ASSERT_TRUE(FileSensor::FromDirectory(dir_.c_str(), CodecImageDecoder(), &sensor).ok());
  SensorMode mode;
  const Status s = sensor->Configure(SensorConfig{}, &mode);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(mode.frames, 3);
  EXPECT_EQ(mode.width, 6);
  EXPECT_EQ(mode.height, 20);
  EXPECT_EQ(mode.format, PixelFormat::kRgb8);

  test::RecordingSink sink;
  ASSERT_TRUE(sensor->CaptureBurst(sink).ok()) << sink.error;
  ASSERT_EQ(sink.frames.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const auto& f = sink.frames[static_cast<size_t>(i)];
    EXPECT_EQ(f.info.index, i);
    EXPECT_EQ(f.info.sequence, static_cast<uint32_t>(i));
    EXPECT_EQ(f.info.timestamp_ns, int64_t{33'000'000} * i);
    EXPECT_EQ(f.strip_heights, (std::vector<int32_t>{16, 4}));
    EXPECT_TRUE(f.ended);
    // a.png holds 10s, b.pnm 20s, c.PPM 30s.
    EXPECT_EQ(f.pixels, std::vector<uint8_t>(6 * 20 * 3, static_cast<uint8_t>(10 * (i + 1))));
  }
}

TEST_F(FileSensorTest, FromFilesKeepsTheGivenOrder) {
  WritePnm("a.pgm", 4, 4, 1, 1);
  WritePnm("b.pgm", 4, 4, 1, 2);
  std::unique_ptr<FileSensor> sensor;
  ASSERT_TRUE(
      FileSensor::FromFiles({Path("b.pgm"), Path("a.pgm")}, CodecImageDecoder(), &sensor).ok());
  SensorMode mode;
  ASSERT_TRUE(sensor->Configure(SensorConfig{}, &mode).ok());
  EXPECT_EQ(mode.format, PixelFormat::kGray8);
  EXPECT_EQ(mode.frames, 2);
  test::RecordingSink sink;
  ASSERT_TRUE(sensor->CaptureBurst(sink).ok());
  ASSERT_EQ(sink.frames.size(), 2u);
  EXPECT_EQ(sink.frames[0].pixels[0], 2);
  EXPECT_EQ(sink.frames[1].pixels[0], 1);
}

TEST_F(FileSensorTest, FramesOfDifferentSizesAreRejectedNamingBoth) {
  WritePng("a.png", 32, 24, 0);
  WritePng("b.png", 64, 48, 0);
  SensorMode mode;
  const Status s = ConfigureDir(&mode);
  EXPECT_EQ(s.code(), Code::kInvalidArgument);
  EXPECT_EQ(std::string(s.message()),
            Path("b.png") + " is 64x48 but " + Path("a.png") + " is 32x24");
}

// `refocus run` sets the limits so that the one Configure of the job refuses a size the
// pipeline cannot take, naming the file.
TEST_F(FileSensorTest, SizeLimitsRefuseNamingTheFirstFile) {
  WritePnm("a.pgm", 8, 8, 1, 0);
  WritePnm("b.pgm", 8, 8, 1, 0);
  std::unique_ptr<FileSensor> sensor;
  ASSERT_TRUE(FileSensor::FromDirectory(dir_.c_str(), CodecImageDecoder(), &sensor).ok());
  SensorMode mode;
  ASSERT_TRUE(sensor->Configure(SensorConfig{}, &mode).ok());  // no limits by default
  sensor->LimitSize(16, 8192, 8192);
  const Status s = sensor->Configure(SensorConfig{}, &mode);
  EXPECT_EQ(s.code(), Code::kUnsupported);
  EXPECT_EQ(std::string(s.message()),
            Path("a.pgm") + ": 8x8 frames: refocus takes 16x16 .. 8192x8192");
  sensor->LimitSize(8, 8, 8);
  EXPECT_TRUE(sensor->Configure(SensorConfig{}, &mode).ok());
}

TEST_F(FileSensorTest, MixedGrayAndColourAreRejectedNamingBoth) {
  WritePnm("a.ppm", 8, 8, 3, 0);
  WritePnm("truedisp.pgm", 8, 8, 1, 0);
  SensorMode mode;
  const Status s = ConfigureDir(&mode);
  EXPECT_EQ(s.code(), Code::kInvalidArgument);
  EXPECT_EQ(std::string(s.message()), Path("truedisp.pgm") + " is GRAY8 but " + Path("a.ppm") +
                                          " is RGB8 (all frames must have one pixel format)");
}

TEST_F(FileSensorTest, EmptyDirectoryIsAnError) {
  ASSERT_TRUE(test::WriteFile(Path("readme.txt"), {'x'}));
  SensorMode mode;
  const Status s = ConfigureDir(&mode);
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_EQ(std::string(s.message()), dir_ + ": no image files (.ppm .pgm .png .jpg)");
}

TEST_F(FileSensorTest, MissingPathsAreErrors) {
  std::unique_ptr<FileSensor> sensor;
  ASSERT_TRUE(FileSensor::FromDirectory("missing/dir", CodecImageDecoder(), &sensor).ok());
  SensorMode mode;
  Status s = sensor->Configure(SensorConfig{}, &mode);
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_STREQ(s.message(), "missing/dir: no such file or directory");

  WritePnm("a.ppm", 8, 8, 3, 0);
  ASSERT_TRUE(
      FileSensor::FromFiles({Path("a.ppm"), Path("gone.ppm")}, CodecImageDecoder(), &sensor).ok());
  s = sensor->Configure(SensorConfig{}, &mode);
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_EQ(std::string(s.message()), Path("gone.ppm") + ": no such file or directory");
}

TEST_F(FileSensorTest, CorruptHeaderFailsConfigureNamingTheFile) {
  WritePnm("a.ppm", 8, 8, 3, 0);
  ASSERT_TRUE(test::WriteFile(Path("b.png"), {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0}));
  SensorMode mode;
  const Status s = ConfigureDir(&mode);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_EQ(std::string(s.message()).rfind(Path("b.png") + ": ", 0), 0u) << s.message();
}

TEST_F(FileSensorTest, RequestedSizeMustMatchAndCaptureNeedsConfigure) {
  WritePnm("a.ppm", 8, 6, 3, 0);
  std::unique_ptr<FileSensor> sensor;
  ASSERT_TRUE(FileSensor::FromDirectory(dir_.c_str(), CodecImageDecoder(), &sensor).ok());
  test::RecordingSink sink;
  EXPECT_EQ(sensor->CaptureBurst(sink).code(), Code::kInvalidArgument);
  SensorConfig config;
  config.width = 640;
  config.height = 480;
  SensorMode mode;
  const Status s = sensor->Configure(config, &mode);
  EXPECT_EQ(s.code(), Code::kUnsupported);
  EXPECT_EQ(std::string(s.message()),
            Path("a.ppm") + ": frames are 8x6, cannot deliver the requested 640x480");
  config.width = 8;
  config.height = 6;
  EXPECT_TRUE(sensor->Configure(config, &mode).ok());
}

TEST_F(FileSensorTest, FileReplacedAfterConfigureFailsTheCapture) {
  WritePnm("a.ppm", 8, 6, 3, 0);
  std::unique_ptr<FileSensor> sensor;
  ASSERT_TRUE(FileSensor::FromDirectory(dir_.c_str(), CodecImageDecoder(), &sensor).ok());
  SensorMode mode;
  ASSERT_TRUE(sensor->Configure(SensorConfig{}, &mode).ok());
  WritePnm("a.ppm", 8, 7, 3, 0);
  test::RecordingSink sink;
  const Status s = sensor->CaptureBurst(sink);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_EQ(std::string(s.message()),
            Path("a.ppm") + " changed since Configure: now 8x7 RGB8, was 8x6 RGB8");
}

}  // namespace
}  // namespace lb
