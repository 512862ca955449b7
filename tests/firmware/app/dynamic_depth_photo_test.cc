// Dynamic Depth in the photos the product makes: the camera's job writes it beside GDepth (with
// the XMP built on the side thread or inline), its items are GDepth's depth image and GImage's
// original byte for byte, independent readers (exiftool, dd_slice.py) find them, and the photo
// with its GDepth part removed still opens for a re-render with the same depth. And a depth map
// stored RangeLinear, by GDepth or by Dynamic Depth, decodes as depth = near + v * (far - near).
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "firmware/app/job.h"
#include "firmware/app/refocusable_photo.h"
#include "firmware/app/rerender.h"
#include "firmware/codecs/png_writer.h"
#include "firmware/refocusable/dynamic_depth.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "sim/synthetic/synthetic_sensor.h"
#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/codecs/test_images.h"
#include "tests/firmware/refocusable/refocusable_test_util.h"

namespace lb {
namespace {

std::string SourceDir() {
  const char* source = getenv("LB_SOURCE_DIR");
  return source != nullptr ? source : ".";
}

std::vector<uint8_t> Item(const DynamicDepthFields& dd, int32_t index) {
  const DynamicDepthItem& item = dd.items[index];
  return std::vector<uint8_t>(item.data, item.data + item.length);
}

// The job's photo, with the XMP built inline (one thread) or beside the render (two).
class JobDynamicDepth : public ::testing::TestWithParam<int32_t> {};

TEST_P(JobDynamicDepth, ThePhotoCarriesBothFormatsAndOpensWithoutGDepth) {
  test::ScratchDir dir;
  const std::string path = dir.Path("photo.jpg");
  SyntheticSensor sensor;
  JobOptions o;
  o.sensor.width = 160;
  o.sensor.height = 120;
  o.pipeline.labels = 16;
  o.threads = GetParam();
  o.focal_35mm = 28;
  Job job;
  ASSERT_TRUE(job.Configure(&sensor, o).ok());
  const Status run = job.Run(path.c_str(), nullptr);
  ASSERT_TRUE(run.ok()) << run.message();
  const std::vector<uint8_t> bytes = test::ReadFile(path);

  // GDepth as before, and Dynamic Depth's items are its depth image and original.
  RefocusableImage gdepth;
  Status s = ReadRefocusable(bytes.data(), bytes.size(), "photo.jpg", &gdepth);
  ASSERT_TRUE(s.ok()) << s.message();
  std::vector<ExtendedXmpChunk> chunks(bytes.size() / kExtendedXmpChunk + 2);
  std::vector<uint8_t> scratch(bytes.size());
  RefocusableBuffers memory;
  memory.chunks = chunks.data();
  memory.chunk_capacity = chunks.size();
  memory.extended = scratch.data();
  memory.extended_capacity = scratch.size();
  RefocusableFields packets;
  std::string_view main, extended;
  ASSERT_TRUE(
      ReadXmpPackets(bytes.data(), bytes.size(), "photo.jpg", memory, &packets, &main, &extended)
          .ok());
  ASSERT_TRUE(HasDynamicDepth(main, extended));
  DynamicDepthFields dd;
  s = ReadDynamicDepthFields(bytes.data(), bytes.size(), "photo.jpg", main, extended, packets.width,
                             packets.height, &dd);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(Item(dd, dd.depth), gdepth.xmp.depth.data);
  ASSERT_GE(dd.original, 0);
  EXPECT_EQ(Item(dd, dd.original), gdepth.xmp.image);
  EXPECT_EQ(dd.format, "RangeInverse");
  EXPECT_EQ(dd.units, "Diopters");
  EXPECT_EQ(dd.near_depth, gdepth.xmp.depth.near_depth);
  EXPECT_EQ(dd.far_depth, gdepth.xmp.depth.far_depth);
  // The camera's intrinsics, normalised by the larger side.
  EXPECT_NE(main.find("ImagingModel:FocalLengthX="), std::string_view::npos) << main;
  EXPECT_NE(main.find("ImagingModel:ImageWidth=\"160\""), std::string_view::npos) << main;

  // Without GDepth the photo opens through Dynamic Depth alone, to the same depth and original.
  const std::vector<uint8_t> dd_only = test::WithoutGDepth(bytes);
  ASSERT_FALSE(dd_only.empty());
  const std::string dd_path = dir.Path("dd_only.jpg");
  ASSERT_TRUE(test::WriteFile(dd_path, dd_only));
  Rerenderer both, alone;
  ASSERT_TRUE(both.Load(path.c_str()).ok());
  s = alone.Load(dd_path.c_str());
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_FALSE(alone.from_primary());
  const ConstImageU16 a = both.disparity_q8(), b = alone.disparity_q8();
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  for (int32_t y = 0; y < a.height; ++y) {
    for (int32_t x = 0; x < a.width; ++x) ASSERT_EQ(a.Row(y)[x], b.Row(y)[x]) << x << "," << y;
  }
  RerenderOptions ro;
  ro.threads = 1;
  s = alone.Render(ro, dir.Path("again.jpg").c_str());
  ASSERT_TRUE(s.ok()) << s.message();
  RefocusableImage again;
  s = ReadRefocusableFile(dir.Path("again.jpg").c_str(), &again);
  EXPECT_TRUE(s.ok()) << s.message();
  EXPECT_FALSE(again.xmp.image.empty());

  // Independent readers: exiftool lists the directory and the DepthMap fields, dd_slice.py slices
  // the items from the end of the file and finds each a valid image of its Mime.
  int code = 0;
  if (test::HaveTool("exiftool")) {
    const std::string out = test::RunTool("exiftool -a -G1 -s '" + path + "' 2>&1", &code);
    EXPECT_EQ(code, 0) << out;
    for (const char* want :
         {"ContainerDirectoryItemMime", "image/jpeg, image/png, image/png, image/jpeg",
          "DepthMapConfidenceURI", "ContainerDirectoryItemLength", "DepthMapFormat", "DepthMapNear",
          "DepthMapFar", "DepthMapUnits", "DepthMapDepthURI", "ImageItemURI"}) {
      EXPECT_NE(out.find(want), std::string::npos) << want << "\n" << out;
    }
    EXPECT_EQ(out.find("Warning"), std::string::npos) << out;
  }
  if (!test::HaveTool("python3")) GTEST_SKIP() << "python3 not installed";
  const std::string out = test::RunTool(
      "python3 '" + SourceDir() + "/tests/firmware/refocusable/dd_slice.py' '" + path + "' 2>&1",
      &code);
  ASSERT_EQ(code, 0) << out;
  const std::string depth_line = "1 image/png " + std::to_string(gdepth.xmp.depth.data.size()) +
                                 " android/depthmap " + std::to_string(gdepth.depth.width) + "x" +
                                 std::to_string(gdepth.depth.height);
  // The confidence map after the depth, the depth's size, the same bytes as GDepth:Confidence.
  ASSERT_FALSE(gdepth.xmp.depth.confidence.empty());
  const std::string confidence_line =
      "2 image/png " + std::to_string(gdepth.xmp.depth.confidence.size()) +
      " android/confidencemap " + std::to_string(gdepth.depth.width) + "x" +
      std::to_string(gdepth.depth.height);
  const std::string original_line =
      "3 image/jpeg " + std::to_string(gdepth.xmp.image.size()) + " android/originalimage 160x120";
  for (const std::string& want : {depth_line, confidence_line, original_line,
                                  std::string("depth 1\n"), std::string("original 3\n")}) {
    EXPECT_NE(out.find(want), std::string::npos) << want << "\n" << out;
  }
}

INSTANTIATE_TEST_SUITE_P(Threads, JobDynamicDepth, ::testing::Values(1, 2),
                         [](const auto& info) { return info.param == 1 ? "Inline" : "Beside"; });

// A 64x48 photo whose 8-bit depth is stored RangeLinear, Near 0.25 and Far 1 (disparities 4 and 1
// px): the left third at Near, the middle at value 128, the right third at Far. With `dd_only`
// its GDepth part is removed, so it is read through Dynamic Depth.
std::vector<uint8_t> LinearPhoto(bool dd_only) {
  constexpr int32_t w = 64, h = 48;
  test::RefocusSample s;
  s.picture = test::MakeTexture(w, h);
  std::vector<uint16_t> values(static_cast<size_t>(w) * h);
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      values[static_cast<size_t>(y) * w + x] = x < w / 3 ? 0 : x < 2 * w / 3 ? 128 : 255;
    }
  }
  GDepthInfo& d = s.xmp.depth;
  EXPECT_TRUE(EncodeGrayPng(MakeView<const uint16_t>(values.data(), w, h), 8, &d.data).ok());
  d.format = "RangeLinear";
  d.near_depth = 0.25;
  d.far_depth = 1.0;
  d.width = w;
  d.height = h;
  EXPECT_TRUE(EncodeYCbCr420(s.picture.View(), 90, &s.xmp.image).ok());
  DynamicDepthExtras extras;
  EXPECT_TRUE(SetDynamicDepth(extras, &s.xmp).ok());
  std::vector<JpegSegment> segments;
  EXPECT_TRUE(BuildXmpSegments(s.xmp, &segments).ok());
  std::vector<uint8_t> bytes = test::WriteRefocusJpeg(s, segments);
  EXPECT_TRUE(AppendDynamicDepthItems(s.xmp, extras, &bytes).ok());
  return dd_only ? test::WithoutGDepth(bytes) : bytes;
}

class RerenderRangeLinear : public ::testing::TestWithParam<bool> {};

TEST_P(RerenderRangeLinear, DepthIsLinearBetweenNearAndFar) {
  test::ScratchDir dir;
  const std::string path = dir.Path("linear.jpg");
  ASSERT_TRUE(test::WriteFile(path, LinearPhoto(GetParam())));
  Rerenderer r;
  const Status loaded = r.Load(path.c_str());
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  ASSERT_EQ(r.working_scale(), 1);
  const ConstImageU16 disp = r.disparity_q8();
  // disparity = 256 / depth (Q8): Near 1024, Far 256, and value 128 at depth
  // 0.25 + 128 / 255 * 0.75 = 0.62647, disparity 408.6 (RangeInverse would give 638).
  EXPECT_EQ(disp.Row(10)[5], 1024);
  EXPECT_EQ(disp.Row(10)[32], 409);
  EXPECT_EQ(disp.Row(10)[60], 256);
  RerenderOptions o;
  o.threads = 1;
  const Status s = r.Render(o, dir.Path("out.jpg").c_str());
  ASSERT_TRUE(s.ok()) << s.message();

  // The camera's page takes it the same way: the engine's RefocusablePhoto, sized beforehand.
  RefocusablePhoto photo;
  ASSERT_TRUE(photo.Configure({.max_width = 64, .max_height = 64, .max_file_bytes = 1 << 20}).ok());
  const std::vector<uint8_t> bytes = test::ReadFile(path);
  ASSERT_TRUE(photo.Decode(bytes.data(), bytes.size(), "linear.jpg").ok());
  EXPECT_EQ(photo.disparity_q8().Row(10)[32], 409);
}

INSTANTIATE_TEST_SUITE_P(Formats, RerenderRangeLinear, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "DynamicDepth" : "GDepth"; });

}  // namespace
}  // namespace lb
