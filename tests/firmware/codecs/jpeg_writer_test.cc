#include "firmware/codecs/jpeg_writer.h"

#include <gtest/gtest.h>
#include <libexif/exif-data.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <string>

#include "firmware/refocusable/base64.h"
#include "tests/firmware/codecs/jpeg_test_util.h"

namespace lb {
namespace {

using test::Ycc420;

JpegMetadata CameraMetadata() {
  JpegMetadata meta;
  meta.make = "LensBlur";
  meta.model = "PS-1";
  meta.software = "lensblur 0.1";
  meta.datetime_original = "2026:11:23 18:30:05";
  meta.f_number = 2.8f;
  return meta;
}

// Encodes `img` strip by strip into `path` the way the firmware does, and commits.
Status EncodeToFile(const Ycc420& img, const std::string& path, const JpegMetadata& meta,
                    int quality = 95) {
  AtomicFile file;
  LB_RETURN_IF_ERROR(file.Open(path.c_str()));
  JpegWriter writer;
  LB_RETURN_IF_ERROR(writer.Begin(&file, img.width, img.height, quality, meta));
  for (int32_t y = 0; y < img.height; y += 16) {
    const int32_t rows = img.height - y < 16 ? img.height - y : 16;
    LB_RETURN_IF_ERROR(writer.WriteStrip(img.Strip(y, rows), rows));
  }
  LB_RETURN_IF_ERROR(writer.Finish());
  return file.Commit();
}

class SizeTest : public ::testing::TestWithParam<std::pair<int32_t, int32_t>> {};

TEST_P(SizeTest, DecodesToTheInputAboveThirtyFiveDb) {
  const auto [width, height] = GetParam();
  const Ycc420 img = test::MakeTexture(width, height);
  test::ScratchDir dir;
  const std::string path = dir.Path("out.jpg");
  Status status = EncodeToFile(img, path, CameraMetadata());
  ASSERT_TRUE(status.ok()) << status.message();
  int32_t w = 0, h = 0;
  std::vector<uint8_t> ycc;
  std::string error;
  ASSERT_TRUE(test::DecodeYcc(test::ReadFile(path), &w, &h, &ycc, &error)) << error;
  EXPECT_EQ(w, width);
  EXPECT_EQ(h, height);
  EXPECT_GT(test::PlanePsnr(img, ycc, 0), 35.0);
  EXPECT_GT(test::PlanePsnr(img, ycc, 1), 35.0);
  EXPECT_GT(test::PlanePsnr(img, ycc, 2), 35.0);
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"out.jpg"});
}

INSTANTIATE_TEST_SUITE_P(Sizes, SizeTest,
                         ::testing::Values(std::make_pair(64, 48), std::make_pair(33, 17),
                                           std::make_pair(101, 75), std::make_pair(16, 16),
                                           std::make_pair(1, 1), std::make_pair(2, 31),
                                           std::make_pair(320, 241), std::make_pair(17, 8)));

TEST(JpegWriterTest, LowQualityIsSmallerAndStillDecodes) {
  const Ycc420 img = test::MakeTexture(96, 64);
  std::vector<uint8_t> high, low;
  ASSERT_TRUE(EncodeYCbCr420(img.View(), 95, &high).ok());
  ASSERT_TRUE(EncodeYCbCr420(img.View(), 30, &low).ok());
  EXPECT_LT(low.size(), high.size());
  int32_t w, h;
  std::vector<uint8_t> ycc;
  std::string error;
  ASSERT_TRUE(test::DecodeYcc(low, &w, &h, &ycc, &error)) << error;
  EXPECT_GT(test::PlanePsnr(img, ycc, 0), 25.0);
}

TEST(JpegWriterTest, SameInputGivesTheSameBytes) {
  const Ycc420 img = test::MakeTexture(77, 45);
  std::vector<uint8_t> a, b;
  ASSERT_TRUE(EncodeYCbCr420(img.View(), 90, &a).ok());
  ASSERT_TRUE(EncodeYCbCr420(img.View(), 90, &b).ok());
  EXPECT_EQ(a, b);
}

// The product promises the same bytes on x86-64 and ARM: an integer-only input (no libm) and a
// digest of the whole file, EXIF included. A libjpeg-turbo or libexif upgrade may change it;
// then check the new file with djpeg and exiftool and update the digest.
TEST(JpegWriterTest, BytesAreTheSameOnEveryPlatform) {
  Ycc420 img;
  img.width = 75;
  img.height = 41;
  img.y.resize(75 * 41);
  img.cb.resize(38 * 21);
  img.cr.resize(38 * 21);
  for (size_t i = 0; i < img.y.size(); ++i) img.y[i] = static_cast<uint8_t>((i * 7) ^ (i >> 5));
  for (size_t i = 0; i < img.cb.size(); ++i) {
    img.cb[i] = static_cast<uint8_t>(96 + i % 64);
    img.cr[i] = static_cast<uint8_t>(160 - i % 48);
  }
  JpegWriter writer;
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(writer.BeginMemory(&jpeg, img.width, img.height, 90, CameraMetadata()).ok());
  for (int32_t y = 0; y < img.height; y += 16) {
    const int32_t rows = img.height - y < 16 ? img.height - y : 16;
    ASSERT_TRUE(writer.WriteStrip(img.Strip(y, rows), rows).ok());
  }
  ASSERT_TRUE(writer.Finish().ok());
  char md5[33];
  Md5Hex(jpeg.data(), jpeg.size(), md5);
  EXPECT_STREQ(md5, "D121B7C576FE25D50C04EE2B6F3ED204") << jpeg.size() << " bytes";
}

TEST(JpegWriterTest, InMemoryEncodeHasJfifAndDecodes) {
  const Ycc420 img = test::MakeTexture(50, 37);
  std::vector<uint8_t> jpeg;
  Status status = EncodeYCbCr420(img.View(), 95, &jpeg);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_GT(jpeg.size(), 20u);
  EXPECT_EQ(jpeg[0], 0xFF);
  EXPECT_EQ(jpeg[1], 0xD8);
  EXPECT_EQ(jpeg[3], 0xE0);  // APP0
  EXPECT_EQ(memcmp(&jpeg[6], "JFIF", 5), 0);
  EXPECT_EQ(jpeg[jpeg.size() - 2], 0xFF);
  EXPECT_EQ(jpeg[jpeg.size() - 1], 0xD9);
  int32_t w, h;
  std::vector<uint8_t> ycc;
  std::string error;
  ASSERT_TRUE(test::DecodeYcc(jpeg, &w, &h, &ycc, &error)) << error;
  EXPECT_EQ(w, 50);
  EXPECT_EQ(h, 37);
  EXPECT_GT(test::PlanePsnr(img, ycc, 0), 35.0);
}

std::string ExifString(ExifData* data, ExifIfd ifd, ExifTag tag) {
  ExifEntry* e = exif_content_get_entry(data->ifd[ifd], tag);
  if (e == nullptr || e->format != EXIF_FORMAT_ASCII || e->size == 0) return "<missing>";
  return std::string(reinterpret_cast<const char*>(e->data),
                     strnlen(reinterpret_cast<const char*>(e->data), e->size));
}

TEST(JpegWriterTest, ExifFieldsReadBackWithLibexif) {
  const Ycc420 img = test::MakeTexture(70, 38);
  test::ScratchDir dir;
  const std::string path = dir.Path("exif.jpg");
  JpegMetadata meta = CameraMetadata();
  meta.focal_35mm = 28;
  ASSERT_TRUE(EncodeToFile(img, path, meta).ok());
  const std::vector<uint8_t> bytes = test::ReadFile(path);
  // EXIF straight after SOI, no JFIF.
  ASSERT_GT(bytes.size(), 12u);
  EXPECT_EQ(bytes[3], 0xE1);
  EXPECT_EQ(memcmp(&bytes[6], "Exif\0\0", 6), 0);

  ExifData* data = exif_data_new_from_file(path.c_str());
  ASSERT_NE(data, nullptr);
  EXPECT_EQ(ExifString(data, EXIF_IFD_0, EXIF_TAG_MAKE), "LensBlur");
  EXPECT_EQ(ExifString(data, EXIF_IFD_0, EXIF_TAG_MODEL), "PS-1");
  EXPECT_EQ(ExifString(data, EXIF_IFD_0, EXIF_TAG_SOFTWARE), "lensblur 0.1");
  EXPECT_EQ(ExifString(data, EXIF_IFD_EXIF, EXIF_TAG_DATE_TIME_ORIGINAL), "2026:11:23 18:30:05");
  const ExifByteOrder order = exif_data_get_byte_order(data);
  ExifEntry* px = exif_content_get_entry(data->ifd[EXIF_IFD_EXIF], EXIF_TAG_PIXEL_X_DIMENSION);
  ExifEntry* py = exif_content_get_entry(data->ifd[EXIF_IFD_EXIF], EXIF_TAG_PIXEL_Y_DIMENSION);
  ExifEntry* fn = exif_content_get_entry(data->ifd[EXIF_IFD_EXIF], EXIF_TAG_FNUMBER);
  ExifEntry* f35 =
      exif_content_get_entry(data->ifd[EXIF_IFD_EXIF], EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM);
  ASSERT_TRUE(px && py && fn && f35);
  EXPECT_EQ(exif_get_short(f35->data, order), 28u);
  EXPECT_EQ(exif_get_long(px->data, order), 70u);
  EXPECT_EQ(exif_get_long(py->data, order), 38u);
  const ExifRational f = exif_get_rational(fn->data, order);
  ASSERT_NE(f.denominator, 0u);
  EXPECT_NEAR(static_cast<double>(f.numerator) / f.denominator, 2.8, 1e-6);
  exif_data_unref(data);
}

TEST(JpegWriterTest, ExtraSegmentsFollowExifInOrder) {
  JpegMetadata meta = CameraMetadata();
  JpegSegment xmp;
  const char kXmp[] = "http://ns.adobe.com/xap/1.0/\0<x:xmpmeta/>";
  xmp.payload.assign(kXmp, kXmp + sizeof(kXmp) - 1);
  JpegSegment app2;
  app2.marker = 0xE2;
  app2.payload.assign(1000, 0x5A);
  meta.extra_segments = {xmp, app2};
  const Ycc420 img = test::MakeTexture(40, 20);
  test::ScratchDir dir;
  ASSERT_TRUE(EncodeToFile(img, dir.Path("x.jpg"), meta).ok());
  const std::vector<uint8_t> b = test::ReadFile(dir.Path("x.jpg"));
  // Walk the markers: SOI, APP1 Exif, APP1 XMP, APP2.
  size_t pos = 2;
  std::vector<std::pair<int, size_t>> segs;
  while (pos + 4 <= b.size() && b[pos] == 0xFF && b[pos + 1] >= 0xE0 && b[pos + 1] <= 0xEF) {
    const size_t len = (static_cast<size_t>(b[pos + 2]) << 8) | b[pos + 3];
    segs.emplace_back(b[pos + 1], pos + 4);
    pos += 2 + len;
  }
  ASSERT_EQ(segs.size(), 3u);
  EXPECT_EQ(segs[0].first, 0xE1);
  EXPECT_EQ(segs[1].first, 0xE1);
  EXPECT_EQ(memcmp(&b[segs[1].second], kXmp, sizeof(kXmp) - 1), 0);
  EXPECT_EQ(segs[2].first, 0xE2);
  EXPECT_EQ(b[segs[2].second + 999], 0x5A);
}

// Segments given late (the refocusable XMP, built beside the render) land where they would have
// at Begin: the file is the same byte for byte, wherever among the strips they come.
TEST(JpegWriterTest, LateSegmentsGiveTheSameFile) {
  JpegSegment xmp;
  const char kXmp[] = "http://ns.adobe.com/xap/1.0/\0<x:xmpmeta/>";
  xmp.payload.assign(kXmp, kXmp + sizeof(kXmp) - 1);
  JpegSegment big;
  big.marker = 0xE2;
  big.payload.assign(JpegSegment::kMaxPayload, 0x33);
  JpegSegment early;
  early.marker = 0xE3;
  early.payload.assign(10, 0x44);
  JpegMetadata meta = CameraMetadata();
  meta.extra_segments = {early, xmp, big};
  // A texture large enough that the encoder's 16 KiB buffer drains several times.
  const Ycc420 img = test::MakeTexture(320, 241);
  test::ScratchDir dir;
  ASSERT_TRUE(EncodeToFile(img, dir.Path("at_begin.jpg"), meta).ok());
  const std::vector<uint8_t> want = test::ReadFile(dir.Path("at_begin.jpg"));
  for (int32_t after : {0, 1, 7, 16}) {  // strips encoded before the segments come
    SCOPED_TRACE(after);
    JpegMetadata later = CameraMetadata();
    later.extra_segments = {early};
    later.segments_later = true;
    AtomicFile file;
    ASSERT_TRUE(file.Open(dir.Path("late.jpg").c_str()).ok());
    JpegWriter writer;
    ASSERT_TRUE(writer.Begin(&file, img.width, img.height, 95, later).ok());
    int32_t strip = 0;
    for (int32_t y = 0; y < img.height; y += 16, ++strip) {
      if (strip == after) {
        EXPECT_TRUE(writer.holding());
        ASSERT_TRUE(writer.InsertSegments({xmp, big}).ok());
      }
      const int32_t rows = img.height - y < 16 ? img.height - y : 16;
      ASSERT_TRUE(writer.WriteStrip(img.Strip(y, rows), rows).ok());
    }
    if (writer.holding()) {
      ASSERT_TRUE(writer.InsertSegments({xmp, big}).ok());
    }
    EXPECT_FALSE(writer.holding());
    ASSERT_TRUE(writer.Finish().ok());
    ASSERT_TRUE(file.Commit().ok());
    EXPECT_TRUE(test::ReadFile(dir.Path("late.jpg")) == want);
  }
}

TEST(JpegWriterTest, LateSegmentsThatNeverComeFailAndLeaveNothing) {
  const Ycc420 img = test::MakeTexture(64, 48);
  test::ScratchDir dir;
  JpegMetadata later = CameraMetadata();
  later.segments_later = true;
  {
    AtomicFile file;
    ASSERT_TRUE(file.Open(dir.Path("late.jpg").c_str()).ok());
    JpegWriter writer;
    ASSERT_TRUE(writer.Begin(&file, img.width, img.height, 95, later).ok());
    for (int32_t y = 0; y < img.height; y += 16) {
      ASSERT_TRUE(writer.WriteStrip(img.Strip(y, 16), 16).ok());
    }
    EXPECT_EQ(writer.Finish().code(), Code::kInvalidArgument);
  }
  {
    AtomicFile file;
    ASSERT_TRUE(file.Open(dir.Path("late.jpg").c_str()).ok());
    JpegWriter writer;
    ASSERT_TRUE(writer.Begin(&file, img.width, img.height, 95, CameraMetadata()).ok());
    EXPECT_FALSE(writer.holding());
    EXPECT_EQ(writer.InsertSegments({}).code(), Code::kInternal);  // none were announced
  }
  EXPECT_TRUE(dir.Entries().empty());
}

TEST(JpegWriterTest, BadArgumentsFailAndAbortTheFile) {
  test::ScratchDir dir;
  const std::string path = dir.Path("bad.jpg");
  JpegMetadata bad_time = CameraMetadata();
  bad_time.datetime_original = "2026-11-23 18:30";
  JpegMetadata bad_segment;
  bad_segment.extra_segments.resize(1);
  bad_segment.extra_segments[0].payload.resize(70000);
  struct Case {
    int32_t w, h;
    int quality;
    const JpegMetadata* meta;
  };
  const JpegMetadata good = CameraMetadata();
  for (const Case& c :
       {Case{0, 10, 90, &good}, Case{10, -1, 90, &good}, Case{10, 10, 0, &good},
        Case{10, 10, 101, &good}, Case{10, 10, 90, &bad_time}, Case{10, 10, 90, &bad_segment}}) {
    AtomicFile file;
    ASSERT_TRUE(file.Open(path.c_str()).ok());
    JpegWriter writer;
    Status status = writer.Begin(&file, c.w, c.h, c.quality, *c.meta);
    EXPECT_FALSE(status.ok());
    EXPECT_NE(std::string(status.message()).find(path), std::string::npos) << status.message();
    EXPECT_TRUE(dir.Entries().empty());
  }
}

TEST(JpegWriterTest, WrongStripsFailMidEncodeAndLeaveNothing) {
  const Ycc420 img = test::MakeTexture(48, 40);
  const Ycc420 narrow = test::MakeTexture(46, 40);
  test::ScratchDir dir;
  const std::string path = dir.Path("mid.jpg");
  enum Fault { kShortMiddle, kTooNarrow, kMissingPlane, kFinishEarly, kTooManyRows };
  for (Fault fault : {kShortMiddle, kTooNarrow, kMissingPlane, kFinishEarly, kTooManyRows}) {
    AtomicFile file;
    ASSERT_TRUE(file.Open(path.c_str()).ok());
    JpegWriter writer;
    ASSERT_TRUE(writer.Begin(&file, img.width, img.height, 90, CameraMetadata()).ok());
    ASSERT_TRUE(writer.WriteStrip(img.Strip(0, 16), 16).ok());
    Status status;
    switch (fault) {
      case kShortMiddle:
        status = writer.WriteStrip(img.Strip(16, 8), 8);
        break;
      case kTooNarrow:
        status = writer.WriteStrip(narrow.Strip(16, 16), 16);
        break;
      case kMissingPlane: {
        ConstPlanarU8 strip = img.Strip(16, 16);
        strip.count = 1;
        status = writer.WriteStrip(strip, 16);
        break;
      }
      case kFinishEarly:
        status = writer.Finish();
        break;
      case kTooManyRows:
        ASSERT_TRUE(writer.WriteStrip(img.Strip(16, 16), 16).ok());
        status = writer.WriteStrip(img.Strip(16, 16), 16);  // only 8 rows are left
        break;
    }
    EXPECT_FALSE(status.ok()) << fault;
    EXPECT_NE(std::string(status.message()).find(path), std::string::npos) << status.message();
    EXPECT_FALSE(writer.active());
    EXPECT_FALSE(file.Commit().ok());
    EXPECT_TRUE(dir.Entries().empty()) << fault;
    // The writer is reusable after a failure.
    std::vector<uint8_t> jpeg;
    EXPECT_TRUE(writer.BeginMemory(&jpeg, 8, 8, 90, JpegMetadata()).ok());
  }
}

// The card fills up while the encoder is writing: the Status names the file and the reason, and
// neither the picture nor its temporary is left (in a child, as the size limit is per process).
TEST(JpegWriterTest, FullDiskMidEncodeLeavesNothing) {
  const Ycc420 img = test::MakeTexture(640, 480);
  test::ScratchDir dir;
  const std::string path = dir.Path("full.jpg");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    signal(SIGXFSZ, SIG_IGN);
    rlimit limit = {20000, 20000};
    if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(10);
    AtomicFile file;
    JpegWriter writer;
    if (!file.Open(path.c_str()).ok()) _exit(11);
    if (!writer.Begin(&file, img.width, img.height, 95, CameraMetadata()).ok()) _exit(12);
    Status status;
    int32_t y = 0;
    for (; y < img.height && status.ok(); y += 16) status = writer.WriteStrip(img.Strip(y, 16), 16);
    if (status.ok()) status = writer.Finish();
    if (status.ok()) _exit(13);
    if (y >= img.height) _exit(14);  // failed during the strips, not only at the end
    if (std::string(status.message()) != path + ": file too large") _exit(15);
    if (writer.active() || file.Commit().ok()) _exit(16);
    _exit(0);
  }
  int wstatus = 0;
  ASSERT_EQ(waitpid(pid, &wstatus, 0), pid);
  ASSERT_TRUE(WIFEXITED(wstatus));
  EXPECT_EQ(WEXITSTATUS(wstatus), 0);
  EXPECT_TRUE(dir.Entries().empty());
}

TEST(JpegWriterTest, AbandonedEncodeLeavesNothing) {
  const Ycc420 img = test::MakeTexture(64, 64);
  test::ScratchDir dir;
  {
    AtomicFile file;
    JpegWriter writer;
    ASSERT_TRUE(file.Open(dir.Path("gone.jpg").c_str()).ok());
    ASSERT_TRUE(writer.Begin(&file, 64, 64, 90, CameraMetadata()).ok());
    ASSERT_TRUE(writer.WriteStrip(img.Strip(0, 16), 16).ok());
  }
  EXPECT_TRUE(dir.Entries().empty());
}

}  // namespace
}  // namespace lb
