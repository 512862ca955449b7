// Re-rendering refocusable JPEGs the product did not write the way it writes them: a phone's,
// whose depth is in its own units and as large as the photo, one whose depth map is smaller
// than the photo by no whole number, one without the all-in-focus original; and starting from
// the focus and blur the file records (GFocus).
#include "firmware/app/rerender.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "firmware/codecs/jpeg_writer.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/codecs/test_images.h"
#include "tests/firmware/refocusable/refocusable_test_util.h"

namespace lb {
namespace {

constexpr int32_t kW = 96, kH = 72;

// Near on the left, far on the right, at `dw` x `dh`.
std::vector<uint16_t> Ramp(int32_t dw, int32_t dh) {
  std::vector<uint16_t> d(static_cast<size_t>(dw) * dh);
  for (int32_t y = 0; y < dh; ++y) {
    for (int32_t x = 0; x < dw; ++x) d[static_cast<size_t>(y) * dw + x] = 4096 - x * 3800 / dw;
  }
  return d;
}

struct Made {
  test::RefocusSample sample;
  std::string path;
};

// A kW x kH photo with a depth map of `dw` x `dh` (8 bit, as phones store it), an original
// unless `original` is false, and GFocus `focus` unless it is null.
bool WritePhoto(const test::ScratchDir& dir, int32_t dw, int32_t dh, bool original,
                const GFocusInfo* focus, double near_depth, double far_depth, Made* out) {
  test::RefocusSample& s = out->sample;
  s.picture = test::MakeTexture(kW, kH);
  std::vector<uint16_t> disp = Ramp(dw, dh);
  const DisparityRange range{0, 4096};
  if (!SetDepthFromDisparity(MakeView<const uint16_t>(disp.data(), dw, dh), range, 8, &s.xmp)
           .ok()) {
    return false;
  }
  if (near_depth > 0) {  // the same values, in a phone's units
    s.xmp.depth.near_depth = near_depth;
    s.xmp.depth.far_depth = far_depth;
  }
  if (original && !EncodeYCbCr420(s.picture.View(), 90, &s.xmp.image).ok()) return false;
  s.xmp.has_focus = focus != nullptr;
  if (focus != nullptr) s.xmp.focus = *focus;
  std::vector<JpegSegment> segments;
  if (!BuildXmpSegments(s.xmp, &segments).ok()) return false;
  out->path = dir.Path("in.jpg");
  return test::WriteFile(out->path, test::WriteRefocusJpeg(s, segments));
}

TEST(RerenderFileFocus, APhonesFileStartsFromItsOwnFocusAndBlur) {
  test::ScratchDir dir;
  // Depth in a phone's units (Google Camera's Near and Far for its table photo), blur a fraction
  // of the width. The ramp is at distance 20 at x = 40; the point is a little off it, as a tap
  // beside an edge would be.
  const GFocusInfo phone = {0.05, 20.0, 0.375, 0.5};
  Made m;
  ASSERT_TRUE(WritePhoto(dir, kW, kH, true, &phone, 12.42, 390.5, &m));
  Rerenderer r;
  const Status loaded = r.Load(m.path.c_str());
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_FALSE(r.from_primary());
  ASSERT_TRUE(r.has_file_focus());
  EXPECT_EQ(r.working_scale(), 1);
  RerenderOptions o;
  r.StartFromFile(&o.render, false, false);
  EXPECT_FLOAT_EQ(o.render.f_number, 2.8f);
  ASSERT_GT(o.render.focus.width, 0);
  // The focus lands as near the point the file names as its distance is found.
  const double cx = o.render.focus.x + o.render.focus.width / 2.0;
  const double cy = o.render.focus.y + o.render.focus.height / 2.0;
  EXPECT_NEAR(cy, 0.5 * kH, 1.0);
  EXPECT_NEAR(cx, 40, 2.0);

  // Rendered so, the new file records the blur the phone did.
  const std::string out = dir.Path("out.jpg");
  const Status rendered = r.Render(o, out.c_str());
  ASSERT_TRUE(rendered.ok()) << rendered.message();
  RefocusableImage back;
  ASSERT_TRUE(ReadRefocusableFile(out.c_str(), &back).ok());
  ASSERT_TRUE(back.xmp.has_focus);
  EXPECT_NEAR(back.xmp.focus.blur_at_infinity, phone.blur_at_infinity,
              0.1 * phone.blur_at_infinity);
  EXPECT_NEAR(back.xmp.focus.focal_point_y, 0.5, 0.02);

  // What the user chose is kept.
  RerenderOptions mine;
  mine.render.f_number = 8.0f;
  mine.render.focus = {10, 10, 16, 16};
  r.StartFromFile(&mine.render, true, true);
  EXPECT_FLOAT_EQ(mine.render.f_number, 8.0f);
  EXPECT_EQ(mine.render.focus.x, 10);
}

TEST(RerenderFileFocus, TheProductsOwnFileStartsAtItsFNumber) {
  test::ScratchDir dir;
  Made m;
  ASSERT_TRUE(WritePhoto(dir, kW / 2, kH / 2, true, nullptr, 0, 0, &m));
  Rerenderer first;
  ASSERT_TRUE(first.Load(m.path.c_str()).ok());
  RerenderOptions o;
  o.render.f_number = 1.4f;
  o.render.focus = {60, 30, 16, 16};
  const std::string at14 = dir.Path("f14.jpg");
  ASSERT_TRUE(first.Render(o, at14.c_str()).ok());

  Rerenderer again;
  const Status loaded = again.Load(at14.c_str());
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_EQ(again.working_scale(), 2);
  RerenderOptions start;
  again.StartFromFile(&start.render, false, false);
  EXPECT_NEAR(start.render.f_number, 1.4f, 0.05f);
  EXPECT_NEAR(start.render.focus.x + start.render.focus.width / 2, 68, 2);
  EXPECT_NEAR(start.render.focus.y + start.render.focus.height / 2, 38, 2);
}

TEST(RerenderFileFocus, ADepthMapSmallerByNoWholeNumberIsScaledToThePhoto) {
  test::ScratchDir dir;
  Made m;
  ASSERT_TRUE(WritePhoto(dir, kW * 2 / 3, kH * 2 / 3, true, nullptr, 0, 0, &m));
  Rerenderer r;
  const Status loaded = r.Load(m.path.c_str());
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_EQ(r.working_scale(), 1);
  const ConstImageU16 d = r.disparity_q8();
  ASSERT_EQ(d.width, kW);
  ASSERT_EQ(d.height, kH);
  EXPECT_GT(d.Row(kH / 2)[0], d.Row(kH / 2)[kW - 1]);  // still near on the left
  const std::string out = dir.Path("out.jpg");
  ASSERT_TRUE(r.Render(RerenderOptions(), out.c_str()).ok());
  RefocusableImage back;
  ASSERT_TRUE(ReadRefocusableFile(out.c_str(), &back).ok());
  EXPECT_EQ(back.depth.width, kW);
  EXPECT_EQ(back.depth.height, kH);
}

TEST(RerenderFileFocus, WithoutAnOriginalThePhotoItselfIsRefocused) {
  test::ScratchDir dir;
  Made m;
  ASSERT_TRUE(WritePhoto(dir, kW, kH, false, nullptr, 0, 0, &m));
  Rerenderer r;
  const Status loaded = r.Load(m.path.c_str());
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_TRUE(r.from_primary());
  EXPECT_EQ(r.width(), kW);
  const std::string out = dir.Path("out.jpg");
  ASSERT_TRUE(r.Render(RerenderOptions(), out.c_str()).ok());
  RefocusableImage back;
  ASSERT_TRUE(ReadRefocusableFile(out.c_str(), &back).ok());
  EXPECT_TRUE(back.xmp.image.empty()) << "no original to pass on";
  EXPECT_EQ(back.depth.width, kW);
}

}  // namespace
}  // namespace lb
