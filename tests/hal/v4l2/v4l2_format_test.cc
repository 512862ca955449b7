#include "hal/v4l2/v4l2_format.h"

#include <gtest/gtest.h>

#include <string>

namespace lb {
namespace {

v4l2_pix_format Pix(uint32_t fourcc, uint32_t w, uint32_t h, uint32_t stride, uint32_t size) {
  v4l2_pix_format p = {};
  p.pixelformat = fourcc;
  p.width = w;
  p.height = h;
  p.bytesperline = stride;
  p.sizeimage = size;
  p.field = V4L2_FIELD_NONE;
  return p;
}

TEST(V4l2FormatTest, MapsTheFormatsThePipelineReads) {
  PixelFormat f;
  ASSERT_TRUE(FourccToPixelFormat(V4L2_PIX_FMT_YUYV, &f));
  EXPECT_EQ(f, PixelFormat::kYuyv);
  ASSERT_TRUE(FourccToPixelFormat(V4L2_PIX_FMT_NV12, &f));
  EXPECT_EQ(f, PixelFormat::kNv12);
  ASSERT_TRUE(FourccToPixelFormat(V4L2_PIX_FMT_RGB24, &f));
  EXPECT_EQ(f, PixelFormat::kRgb8);
  ASSERT_TRUE(FourccToPixelFormat(V4L2_PIX_FMT_BGR24, &f));
  EXPECT_EQ(f, PixelFormat::kBgr8);
  // Decoded by the sensor: the sink receives RGB.
  ASSERT_TRUE(FourccToPixelFormat(V4L2_PIX_FMT_MJPEG, &f));
  EXPECT_EQ(f, PixelFormat::kRgb8);
  ASSERT_TRUE(FourccToPixelFormat(V4L2_PIX_FMT_JPEG, &f));
  EXPECT_EQ(f, PixelFormat::kRgb8);
  EXPECT_FALSE(FourccToPixelFormat(V4L2_PIX_FMT_H264, &f));
  EXPECT_STREQ(FourccName(V4L2_PIX_FMT_YUYV).text, "YUYV");
}

TEST(V4l2FormatTest, PrefersYuyvThenNv12ThenRgb) {
  uint32_t chosen = 0;
  const uint32_t all[] = {V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_RGB24, V4L2_PIX_FMT_NV12,
                          V4L2_PIX_FMT_YUYV};
  ASSERT_TRUE(ChooseFourcc("/dev/video0", all, 4, 0, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_YUYV);
  ASSERT_TRUE(ChooseFourcc("/dev/video0", all, 3, 0, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_NV12);
  ASSERT_TRUE(ChooseFourcc("/dev/video0", all, 2, 0, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_RGB24);
  const uint32_t bgr[] = {V4L2_PIX_FMT_BGR24};
  ASSERT_TRUE(ChooseFourcc("/dev/video0", bgr, 1, 0, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_BGR24);
}

TEST(V4l2FormatTest, AnExplicitFormatMustBeOfferedAndReadable) {
  uint32_t chosen = 0;
  const uint32_t offered[] = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_RGB24, V4L2_PIX_FMT_MJPEG};
  ASSERT_TRUE(ChooseFourcc("/dev/video0", offered, 3, V4L2_PIX_FMT_RGB24, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_RGB24);
  Status s = ChooseFourcc("/dev/video0", offered, 3, V4L2_PIX_FMT_NV12, &chosen);
  EXPECT_EQ(s.code(), Code::kUnsupported);
  EXPECT_NE(std::string(s.message()).find("NV12"), std::string::npos) << s.message();
  ASSERT_TRUE(ChooseFourcc("/dev/video0", offered, 3, V4L2_PIX_FMT_MJPEG, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_MJPEG);
  s = ChooseFourcc("/dev/video0", offered, 3, V4L2_PIX_FMT_JPEG, &chosen);
  EXPECT_EQ(s.code(), Code::kUnsupported);
  s = ChooseFourcc("/dev/video0", offered, 3, V4L2_PIX_FMT_H264, &chosen);
  EXPECT_EQ(s.code(), Code::kUnsupported);
  EXPECT_NE(std::string(s.message()).find("not one the pipeline reads"), std::string::npos);
}

TEST(V4l2FormatTest, MjpegOnlyWhereNothingUncompressedHasTheSize) {
  uint32_t chosen = 0;
  const uint32_t offered[] = {V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_JPEG,
                              V4L2_PIX_FMT_NV12};
  // YUYV and NV12 at the size: uncompressed first, whatever the driver's order.
  const bool all[] = {true, true, true, true};
  ASSERT_TRUE(ChooseFourcc("/dev/video0", offered, all, 4, 0, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_YUYV);
  const bool nv12[] = {true, false, true, true};
  ASSERT_TRUE(ChooseFourcc("/dev/video0", offered, nv12, 4, 0, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_NV12);
  // Only the compressed ones have it: MJPEG before JPEG.
  const bool compressed[] = {true, false, true, false};
  ASSERT_TRUE(ChooseFourcc("/dev/video0", offered, compressed, 4, 0, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_MJPEG);
  const bool jpeg[] = {false, false, true, false};
  ASSERT_TRUE(ChooseFourcc("/dev/video0", offered, jpeg, 4, 0, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_JPEG);
  // Nothing has it: uncompressed, at the size the driver picks.
  const bool none[] = {false, false, false, false};
  ASSERT_TRUE(ChooseFourcc("/dev/video0", offered, none, 4, 0, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_YUYV);
  ASSERT_TRUE(ChooseFourcc("/dev/video0", offered, none, 1, 0, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_MJPEG);
  // Asked for by name, the size does not matter.
  ASSERT_TRUE(ChooseFourcc("/dev/video0", offered, none, 4, V4L2_PIX_FMT_JPEG, &chosen).ok());
  EXPECT_EQ(chosen, V4L2_PIX_FMT_JPEG);
}

TEST(V4l2FormatTest, NothingReadableNamesWhatTheDeviceOffers) {
  uint32_t chosen = 0;
  const uint32_t offered[] = {V4L2_PIX_FMT_H264, V4L2_PIX_FMT_SRGGB10};
  Status s = ChooseFourcc("/dev/video3", offered, 2, 0, &chosen);
  ASSERT_EQ(s.code(), Code::kUnsupported);
  std::string m = s.message();
  EXPECT_NE(m.find("/dev/video3"), std::string::npos) << m;
  EXPECT_NE(m.find("H264"), std::string::npos) << m;
  EXPECT_NE(m.find("RG10"), std::string::npos) << m;
  EXPECT_NE(m.find("MJPG or JPEG"), std::string::npos) << m;
}

TEST(V4l2FormatTest, MjpegLayoutIsCompressedRgb) {
  V4l2Layout l;
  // UVC drivers report no bytesperline and the largest frame as sizeimage; odd sizes are fine.
  ASSERT_TRUE(LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_MJPEG, 1279, 719, 0, 1843200),
                               V4L2_PIX_FMT_MJPEG, &l)
                  .ok());
  EXPECT_TRUE(l.compressed);
  EXPECT_EQ(l.format, PixelFormat::kRgb8);
  EXPECT_EQ(l.width, 1279);
  EXPECT_EQ(l.height, 719);
  EXPECT_EQ(l.stride, 0);
  EXPECT_EQ(l.min_bytes, kMinJpegBytes);
  ASSERT_TRUE(
      LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_YUYV, 64, 48, 0, 0), V4L2_PIX_FMT_YUYV, &l)
          .ok());
  EXPECT_FALSE(l.compressed);
  EXPECT_EQ(LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_MJPEG, 9000, 48, 0, 0),
                             V4L2_PIX_FMT_MJPEG, &l)
                .code(),
            Code::kUnsupported);
}

TEST(V4l2FormatTest, PaddedYuyvLayout) {
  V4l2Layout l;
  ASSERT_TRUE(LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_YUYV, 640, 480, 1344, 1344 * 480),
                               V4L2_PIX_FMT_YUYV, &l)
                  .ok());
  EXPECT_EQ(l.format, PixelFormat::kYuyv);
  EXPECT_EQ(l.width, 640);
  EXPECT_EQ(l.height, 480);
  EXPECT_EQ(l.stride, 1344);
  EXPECT_EQ(l.min_bytes, 1344u * 480u);
}

TEST(V4l2FormatTest, Nv12PlaneFollowsTheLumaPlane) {
  V4l2Layout l;
  ASSERT_TRUE(LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_NV12, 64, 48, 64, 64 * 72),
                               V4L2_PIX_FMT_NV12, &l)
                  .ok());
  EXPECT_EQ(l.uv_offset, 64u * 48u);
  EXPECT_EQ(l.min_bytes, 64u * 72u);
  // A zero bytesperline means "packed".
  ASSERT_TRUE(
      LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_RGB24, 10, 4, 0, 0), V4L2_PIX_FMT_RGB24, &l)
          .ok());
  EXPECT_EQ(l.stride, 30);
}

TEST(V4l2FormatTest, RejectsLayoutsThatCannotHoldAFrame) {
  V4l2Layout l;
  // Stride shorter than the pixels.
  EXPECT_EQ(LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_YUYV, 640, 480, 1000, 0),
                             V4L2_PIX_FMT_YUYV, &l)
                .code(),
            Code::kCorruptData);
  // Image size that misses the chroma plane.
  EXPECT_EQ(LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_NV12, 64, 48, 64, 64 * 48),
                             V4L2_PIX_FMT_NV12, &l)
                .code(),
            Code::kCorruptData);
  // Odd NV12 height, odd YUYV width.
  EXPECT_EQ(
      LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_NV12, 64, 47, 64, 0), V4L2_PIX_FMT_NV12, &l)
          .code(),
      Code::kUnsupported);
  EXPECT_EQ(
      LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_YUYV, 63, 48, 128, 0), V4L2_PIX_FMT_YUYV, &l)
          .code(),
      Code::kUnsupported);
  // Zero or oversized frames.
  EXPECT_EQ(
      LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_RGB24, 0, 48, 0, 0), V4L2_PIX_FMT_RGB24, &l)
          .code(),
      Code::kUnsupported);
  EXPECT_EQ(LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_RGB24, 9000, 48, 0, 0),
                             V4L2_PIX_FMT_RGB24, &l)
                .code(),
            Code::kUnsupported);
}

TEST(V4l2FormatTest, DriverSwappingTheFormatIsReported) {
  V4l2Layout l;
  Status s = LayoutFromFormat("/dev/video0", Pix(V4L2_PIX_FMT_MJPEG, 640, 480, 0, 100000),
                              V4L2_PIX_FMT_YUYV, &l);
  ASSERT_EQ(s.code(), Code::kUnsupported);
  EXPECT_NE(std::string(s.message()).find("MJPG"), std::string::npos) << s.message();
}

TEST(V4l2FormatTest, InterlacedIsRefused) {
  V4l2Layout l;
  v4l2_pix_format p = Pix(V4L2_PIX_FMT_YUYV, 640, 480, 1280, 0);
  p.field = V4L2_FIELD_INTERLACED;
  EXPECT_EQ(LayoutFromFormat("/dev/video0", p, V4L2_PIX_FMT_YUYV, &l).code(), Code::kUnsupported);
}

}  // namespace
}  // namespace lb
