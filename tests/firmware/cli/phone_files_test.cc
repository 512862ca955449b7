// `refocus info` and `refocus rerender` on refocusable JPEGs as a user meets them: phones' Lens
// Blur photos (../shared/data/phone-depth; skipped when absent), the product's own, a plain
// JPEG, and one without the all-in-focus original.
#include <sys/stat.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "firmware/app/refocusable.h"
#include "firmware/codecs/image_file.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "tests/firmware/cli/cli_fixture.h"
#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/codecs/test_images.h"
#include "tests/firmware/refocusable/refocusable_test_util.h"

namespace lb {
namespace {

using clitest::Cli;
using clitest::Result;
using test::Bytes;

std::string PhoneDir() {
  const char* root = std::getenv("LB_SOURCE_DIR");
  const std::string dir = std::string(root ? root : ".") + "/../shared/data/phone-depth";
  struct stat st;
  return stat(dir.c_str(), &st) == 0 && S_ISDIR(st.st_mode) ? dir : std::string();
}

struct PhoneFile {
  const char* name;
  int32_t width, height;
  const char* near_depth;  // as info prints it
};

const PhoneFile kPhoneFiles[] = {
    {"lensblur_table.jpg", 768, 1024, "12.4236"},
    {"lensblur_xt912.jpg", 1536, 2048, "18.8495"},
    {"lensblur_depthy1.jpg", 580, 1024, "9.61551"},
};

bool Has(const std::string& text, const std::string& line) {
  return text.find(line + "\n") != std::string::npos;
}

// Whether a line of `text` begins with `start`.
bool StartsLine(const std::string& text, const std::string& start) {
  return ("\n" + text).find("\n" + start) != std::string::npos;
}

// The rest of the line that begins with `key` ("" when there is none).
std::string LineValue(const std::string& text, const std::string& key) {
  const std::string lines = "\n" + text;
  size_t at = lines.find("\n" + key);
  if (at == std::string::npos) return "";
  at += 1 + key.size();
  return lines.substr(at, lines.find('\n', at) - at);
}

// The decoded luma of a JPEG; empty when it does not decode.
std::vector<int> Luma(const std::string& path, int32_t* width, int32_t* height) {
  ImageFileInfo info;
  std::vector<uint8_t> rgb;
  const std::string text = clitest::Slurp(path);
  const Bytes bytes(text.begin(), text.end());
  if (!ReadImageMemory(bytes.data(), bytes.size(), path.c_str(), &info, &rgb).ok() ||
      info.format != PixelFormat::kRgb8) {
    return {};
  }
  *width = info.width;
  *height = info.height;
  std::vector<int> y(rgb.size() / 3);
  for (size_t i = 0; i < y.size(); ++i) {
    y[i] = (77 * rgb[3 * i] + 150 * rgb[3 * i + 1] + 29 * rgb[3 * i + 2]) >> 8;
  }
  return y;
}

double MeanDifference(const std::vector<int>& a, const std::vector<int>& b) {
  if (a.size() != b.size() || a.empty()) return -1.0;
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) sum += std::abs(a[i] - b[i]);
  return sum / static_cast<double>(a.size());
}

class PhoneFiles : public Cli {
 protected:
  void SetUp() override {
    Cli::SetUp();
    dir = PhoneDir();
    if (dir.empty()) GTEST_SKIP() << "../shared/data/phone-depth is absent: no phone files to read";
  }
  std::string dir;
};

TEST_F(PhoneFiles, InfoSaysWhatEachCarries) {
  for (const PhoneFile& f : kPhoneFiles) {
    SCOPED_TRACE(f.name);
    const Result r = Run({"info", dir + "/" + f.name});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    const std::string size = std::to_string(f.width) + "x" + std::to_string(f.height);
    for (const std::string& line :
         {std::string("formats: GDepth GImage GFocus"), "primary: " + size, "depth: " + size,
          std::string("depth format: RangeInverse"), std::string("depth near: ") + f.near_depth,
          std::string("depth mime: image/png"), std::string("depth colour: 8-bit RGBA"),
          "original: " + size + " image/jpeg (GImage)", std::string("confidence: none")}) {
      EXPECT_TRUE(Has(r.out, line)) << "no line '" << line << "' in\n" << r.out;
    }
    EXPECT_NE(r.out.find("\nfocus point: 0."), std::string::npos) << r.out;
  }
}

// Each file renders with its own focus and with a new one; both outputs decode, differ from
// each other, and are refocusable again. The render with the file's own focus looks more like
// the phone's own render (the primary image) than the one focused elsewhere does.
TEST_F(PhoneFiles, RerenderWithItsOwnFocusAndANewOne) {
  for (const PhoneFile& f : kPhoneFiles) {
    SCOPED_TRACE(f.name);
    const std::string in = dir + "/" + f.name;
    const std::string own = dir_ + "/own.jpg", moved = dir_ + "/moved.jpg";
    Result r = Run({"rerender", in, "--out", own});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    // The top-left corner: in these photos, not where the phone focused.
    const std::string point = std::to_string(f.width / 10) + "," + std::to_string(f.height / 10);
    r = Run({"rerender", in, "--focus", point, "--out", moved});
    ASSERT_EQ(r.exit_code, 0) << r.err;

    int32_t w = 0, h = 0;
    const std::vector<int> phone = Luma(in, &w, &h);
    const std::vector<int> a = Luma(own, &w, &h);
    ASSERT_FALSE(a.empty()) << own << " does not decode";
    EXPECT_EQ(w, f.width);
    EXPECT_EQ(h, f.height);
    const std::vector<int> b = Luma(moved, &w, &h);
    ASSERT_FALSE(b.empty()) << moved << " does not decode";
    const double between = MeanDifference(a, b);
    const double own_to_phone = MeanDifference(a, phone);
    const double moved_to_phone = MeanDifference(b, phone);
    printf("%s: own vs moved focus %.2f levels; to the phone's render: own %.2f, moved %.2f\n",
           f.name, between, own_to_phone, moved_to_phone);
    EXPECT_GT(between, 1.0) << "moving the focus changed nothing";
    EXPECT_LT(own_to_phone, moved_to_phone);

    for (const std::string& path : {own, moved}) {
      RefocusableImage back;
      const Status s = ReadRefocusableFile(path.c_str(), &back);
      ASSERT_TRUE(s.ok()) << s.message();
      EXPECT_EQ(back.depth.width, f.width);
      EXPECT_FALSE(back.xmp.image.empty());
      EXPECT_TRUE(back.xmp.has_focus);
    }
  }
}

class Info : public Cli {};

TEST_F(Info, OnTheProductsOwnFile) {
  const std::string photo = dir_ + "/photo.jpg";
  Result r = Run({"run", "--synthetic", "--size", "320x240", "--geometry", "rectified",
                  "--f-number", "1.4", "--focus", "50,50", "--out", photo});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = Run({"info", photo});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  for (const char* line :
       {"formats: GDepth GImage GFocus DynamicDepth", "primary: 320x240", "depth from: GDepth",
        "depth format: RangeInverse", "depth mime: image/png", "depth colour: 16-bit grey",
        "original: 320x240 image/jpeg (GImage)"}) {
    EXPECT_TRUE(Has(r.out, line)) << "no line '" << line << "' in\n" << r.out;
  }
  // The confidence map, the depth's size, in both formats.
  const std::string size = LineValue(r.out, "depth: ");
  EXPECT_FALSE(size.empty()) << r.out;
  EXPECT_TRUE(StartsLine(r.out, "confidence: " + size + " image/png, ")) << r.out;
  EXPECT_NE(r.out.find("(GDepth)\n"), std::string::npos) << r.out;
  EXPECT_TRUE(StartsLine(r.out, "dynamic depth confidence: " + size + " 8-bit grey image/png, "))
      << r.out;
  EXPECT_NE(r.out.find("\ndynamic depth original: 320x240 image/jpeg, "), std::string::npos)
      << r.out;
  // Re-rendered with no lens settings, it starts where `run` left it.
  const std::string again = dir_ + "/again.jpg";
  r = Run({"rerender", photo, "--out", again});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("at f/1.4"), std::string::npos) << r.out;
}

// `refocus run` writes Dynamic Depth beside GDepth: exiftool lists its directory and DepthMap
// fields, dd_slice.py (an independent parser) slices its items from the end of the file and finds
// the depth and the original valid images of their Mime, and with the GDepth part removed the
// photo still tells what it carries and rerenders, carrying both formats again.
TEST_F(Info, TheProductsDynamicDepthOpensWithoutGDepth) {
  const std::string photo = dir_ + "/photo.jpg";
  Result r =
      Run({"run", "--synthetic", "--size", "160x120", "--geometry", "rectified", "--out", photo});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int code = 0;
  if (test::HaveTool("exiftool")) {
    const std::string out = test::RunTool("exiftool -a -G1 -s '" + photo + "' 2>&1", &code);
    EXPECT_EQ(code, 0) << out;
    for (const char* want :
         {"[XMP-Device]", "ContainerDirectoryItemMime",
          "image/jpeg, image/png, image/png, image/jpeg", "DepthMapConfidenceURI",
          "android/confidencemap", "ContainerDirectoryItemLength", "DepthMapFormat", "RangeInverse",
          "DepthMapNear", "DepthMapFar", "DepthMapUnits", "Diopters", "DepthMapDepthURI",
          "android/depthmap", "ImageItemURI", "android/originalimage"}) {
      EXPECT_NE(out.find(want), std::string::npos) << want << "\n" << out;
    }
  }
  if (test::HaveTool("python3")) {
    const char* source = std::getenv("LB_SOURCE_DIR");
    const std::string out =
        test::RunTool("python3 '" + std::string(source ? source : ".") +
                          "/tests/firmware/refocusable/dd_slice.py' '" + photo + "' 2>&1",
                      &code);
    ASSERT_EQ(code, 0) << out;
    EXPECT_NE(out.find(" image/png "), std::string::npos) << out;
    EXPECT_NE(out.find(" android/originalimage 160x120\n"), std::string::npos) << out;
    EXPECT_NE(out.find("depth 1\n"), std::string::npos) << out;
    EXPECT_NE(out.find("original 3\n"), std::string::npos) << out;
  }

  const std::string text = clitest::Slurp(photo);
  const Bytes dd_only = test::WithoutGDepth(Bytes(text.begin(), text.end()));
  ASSERT_FALSE(dd_only.empty());
  const std::string stripped = dir_ + "/dd_only.jpg";
  ASSERT_TRUE(test::WriteFile(stripped, dd_only));
  r = Run({"info", stripped});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  for (const char* line :
       {"formats: DynamicDepth", "depth from: Dynamic Depth",
        "original: 160x120 image/jpeg (Dynamic Depth Original)", "depth units: Diopters"}) {
    EXPECT_TRUE(Has(r.out, line)) << "no line '" << line << "' in\n" << r.out;
  }
  const std::string size = LineValue(r.out, "depth: ");
  EXPECT_TRUE(StartsLine(r.out, "confidence: " + size + " image/png, ")) << r.out;
  EXPECT_NE(r.out.find(" bytes (Dynamic Depth)\n"), std::string::npos) << r.out;
  r = Run({"rerender", stripped, "--focus", "80,60", "--out", Out()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  r = Run({"info", Out()});
  EXPECT_TRUE(Has(r.out, "formats: GDepth GImage GFocus DynamicDepth")) << r.out;
}

TEST_F(Info, APlainJpegCarriesNone) {
  std::vector<uint8_t> rgb(64 * 48 * 3, 90);
  Bytes jpg;
  ASSERT_TRUE(test::EncodeJpeg(64, 48, 3, rgb.data(), 90, false, &jpg));
  const std::string path = dir_ + "/plain.jpg";
  ASSERT_TRUE(test::WriteFile(path, jpg));
  const Result r = Run({"info", path});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(Has(r.out, "primary: 64x48")) << r.out;
  EXPECT_TRUE(Has(r.out, "formats: none")) << r.out;
}

// A file with depth but no GImage: refocused from the photo itself, with one line that says so.
TEST_F(Info, WithoutAnOriginalRerenderWarnsOnce) {
  const int32_t w = 64, h = 48;
  std::vector<uint16_t> depth(static_cast<size_t>(w) * h);
  for (size_t i = 0; i < depth.size(); ++i) depth[i] = static_cast<uint16_t>(256 + i % w * 64);
  JpegMetadata meta;
  ASSERT_TRUE(BuildRefocusableSegments(MakeView<const uint16_t>(depth.data(), w, h),
                                       DisparityRange{0, 16 << 8}, std::vector<uint8_t>(),
                                       FocusUsed(), w, &meta.extra_segments)
                  .ok());
  std::vector<uint8_t> luma(static_cast<size_t>(w) * 16, 120), chroma(w / 2 * 8, 128), bytes;
  ConstPlanarU8 strip;
  strip.count = 3;
  strip.planes[0] = {luma.data(), w, 16, 1, w};
  strip.planes[1] = {chroma.data(), w / 2, 8, 1, w / 2};
  strip.planes[2] = {chroma.data(), w / 2, 8, 1, w / 2};
  JpegWriter writer;
  ASSERT_TRUE(writer.BeginMemory(&bytes, w, h, 90, meta).ok());
  for (int32_t y = 0; y < h; y += 16) ASSERT_TRUE(writer.WriteStrip(strip, 16).ok());
  ASSERT_TRUE(writer.Finish().ok());
  const std::string path = dir_ + "/blurred.jpg";
  ASSERT_TRUE(test::WriteFile(path, bytes));

  Result r = Run({"info", path});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Has(r.out, "formats: GDepth GFocus")) << r.out;
  EXPECT_NE(r.out.find("\noriginal: none"), std::string::npos) << r.out;

  r = Run({"rerender", path, "--out", Out()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("warning: " + path + " has no all-in-focus original (GImage)"),
            std::string::npos)
      << r.err;
  RefocusableImage back;
  EXPECT_TRUE(ReadRefocusableFile(Out().c_str(), &back).ok());
}

}  // namespace
}  // namespace lb
