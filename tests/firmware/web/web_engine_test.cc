// The server with the camera's own renderer (EngineBackend) on files it cannot refocus: a photo
// larger than the camera's, an all-in-focus original far over any sensor, and extended XMP cut
// into more pieces than the renderer takes. The page gets 422 for each, /api/info says the same
// (refocusable: false), nothing is logged as an error, and no answer shows a folder's path.
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "firmware/app/refocusable.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/web/engine_backend.h"
#include "firmware/web/web_server.h"
#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/web/http_client.h"

namespace lb {
namespace {

using test::Http;
using test::HttpResponse;

constexpr char kToken[] = "test-token-0123456789";
const std::string kAuth = std::string("Authorization: Bearer ") + kToken + "\r\n";

class Lines final : public LogSink {
 public:
  void Write(LogLevel level, const char* text) override {
    std::lock_guard<std::mutex> lock(mutex_);
    all_ += text;
    all_ += "\n";
    if (level == LogLevel::kError) errors_ += std::string(text) + "\n";
  }
  std::string all() {
    std::lock_guard<std::mutex> lock(mutex_);
    return all_;
  }
  std::string errors() {
    std::lock_guard<std::mutex> lock(mutex_);
    return errors_;
  }

 private:
  std::mutex mutex_;
  std::string all_, errors_;
};

// A flat grey JPEG, written a strip at a time (a 9000x9000 one without
// holding its pixels).
std::vector<uint8_t> FlatJpeg(int32_t width, int32_t height) {
  test::Ycc420 strip;
  strip.width = width;
  strip.height = JpegWriter::kStripRows;
  strip.y.assign(static_cast<size_t>(width) * strip.height, 128);
  strip.cb.assign(static_cast<size_t>(strip.cwidth()) * strip.cheight(), 128);
  strip.cr = strip.cb;
  std::vector<uint8_t> out;
  JpegWriter writer;
  EXPECT_TRUE(writer.BeginMemory(&out, width, height, 50, JpegMetadata()).ok());
  for (int32_t y = 0; y < height; y += JpegWriter::kStripRows) {
    const int32_t rows = std::min(JpegWriter::kStripRows, height - y);
    EXPECT_TRUE(writer.WriteStrip(strip.Strip(0, rows), rows).ok());
  }
  EXPECT_TRUE(writer.Finish().ok());
  return out;
}

// The extended-XMP chunks of `segments` (after the main packet) cut again into `pieces`.
void Rechunk(size_t pieces, std::vector<JpegSegment>* segments) {
  const size_t sig = strlen(kExtendedXmpSignature) + 1, head = sig + 32 + 8;
  ASSERT_GT(segments->size(), 1u) << "the data must need extended XMP";
  std::string data;
  const std::vector<uint8_t> first = (*segments)[1].payload;
  for (size_t i = 1; i < segments->size(); ++i) {
    const std::vector<uint8_t>& p = (*segments)[i].payload;
    data.append(p.begin() + static_cast<long>(head), p.end());
  }
  segments->resize(1);
  for (size_t i = 0; i < pieces; ++i) {
    const size_t offset = data.size() * i / pieces, end = data.size() * (i + 1) / pieces;
    JpegSegment s;
    s.payload.assign(first.begin(), first.begin() + static_cast<long>(sig + 32 + 4));
    for (int b = 3; b >= 0; --b) s.payload.push_back(static_cast<uint8_t>(offset >> (8 * b)));
    s.payload.insert(s.payload.end(), data.begin() + static_cast<long>(offset),
                     data.begin() + static_cast<long>(end));
    segments->push_back(std::move(s));
  }
  ASSERT_EQ(segments->size(), pieces + 1);
}

// A refocusable 640x480 photo: a smooth depth ramp, `original` as its GImage, its extended XMP
// in `pieces` chunks (0: as the writer cuts it).
void WritePhoto(const std::string& path, const std::vector<uint8_t>& original, size_t pieces) {
  constexpr int32_t kW = 640, kH = 480, kDw = 160, kDh = 120;
  std::vector<uint16_t> disp(static_cast<size_t>(kDw) * kDh);
  for (int32_t y = 0; y < kDh; ++y) {
    for (int32_t x = 0; x < kDw; ++x) disp[static_cast<size_t>(y) * kDw + x] = (x + y) * 8;
  }
  DisparityRange range;
  range.min_q8 = 0;
  range.max_q8 = 16 * 256;
  JpegMetadata meta;
  ASSERT_TRUE(
      BuildRefocusableSegments(MakeView(static_cast<const uint16_t*>(disp.data()), kDw, kDh), range,
                               original, FocusUsed(), kW, &meta.extra_segments)
          .ok());
  if (pieces > 0) Rechunk(pieces, &meta.extra_segments);
  const test::Ycc420 image = test::MakeTexture(kW, kH);
  std::vector<uint8_t> jpeg;
  JpegWriter writer;
  ASSERT_TRUE(writer.BeginMemory(&jpeg, kW, kH, 90, meta).ok());
  for (int32_t y = 0; y < kH; y += JpegWriter::kStripRows) {
    ASSERT_TRUE(writer.WriteStrip(image.Strip(y, JpegWriter::kStripRows), 16).ok());
  }
  ASSERT_TRUE(writer.Finish().ok());
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(jpeg.data()), static_cast<std::streamsize>(jpeg.size()));
}

std::vector<uint8_t> TextureJpeg(int32_t w, int32_t h) {
  std::vector<uint8_t> jpeg;
  EXPECT_TRUE(EncodeYCbCr420(test::MakeTexture(w, h).View(), 95, &jpeg).ok());
  return jpeg;
}

class WebEngineTest : public ::testing::Test {
 protected:
  void Start(int32_t width, int32_t height) {
    backend_ = std::make_unique<EngineBackend>(width, height, 1, &log_, &camera_busy_);
    ASSERT_TRUE(backend_->Ready().ok());
    WebServerOptions o;
    o.token = kToken;
    o.web_root = photos_.dir();
    o.photo_dir = photo_dir_.empty() ? photos_.dir() : photo_dir_;
    server_ = std::make_unique<WebServer>(o, backend_.get(), &log_);
    ASSERT_TRUE(server_->Start().ok());
  }
  // The render thread runs at a lower priority than the tests beside it, so on a busy machine a
  // render that takes 2 s alone can take 20: the verdict is checked here, not the speed.
  static constexpr int kRenderMs = 120000;
  HttpResponse Info(const std::string& name) {
    return Http(server_->port(), "GET", "/api/info/" + name, kAuth, "", kRenderMs);
  }
  HttpResponse Preview(const std::string& name) {
    return Http(server_->port(), "POST", "/api/preview",
                kAuth + "Content-Type: application/x-www-form-urlencoded\r\n",
                "name=" + name + "&x0=0.5&y0=0.5&f=2", kRenderMs);
  }
  // The page's verdict on `name`: /api/info and a preview agree.
  void ExpectNotRefocusable(const std::string& name) {
    HttpResponse info = Info(name);
    EXPECT_EQ(info.status, 200) << info.body;
    EXPECT_NE(info.body.find("\"refocusable\":false"), std::string::npos) << info.body;
    HttpResponse preview = Preview(name);
    EXPECT_EQ(preview.status, 422) << preview.body;
    EXPECT_NE(preview.body.find(name), std::string::npos) << preview.body;
    EXPECT_EQ(preview.body.find(photos_.dir()), std::string::npos) << preview.body;
    EXPECT_EQ(log_sink_.errors(), "") << log_sink_.all();
  }

  test::ScratchDir photos_;
  std::string photo_dir_;
  Lines log_sink_;
  Log log_{&log_sink_, LogLevel::kDebug};
  std::atomic<bool> camera_busy_{false};
  std::unique_ptr<EngineBackend> backend_;
  std::unique_ptr<WebServer> server_;
};

TEST_F(WebEngineTest, AWellMadePhotoIsRefocusable) {
  WritePhoto(photos_.Path("IMG_ok.jpg"), TextureJpeg(640, 480), 0);
  Start(640, 480);
  HttpResponse info = Info("IMG_ok.jpg");
  EXPECT_EQ(info.status, 200);
  EXPECT_NE(info.body.find("\"refocusable\":true"), std::string::npos) << info.body;
  EXPECT_EQ(Preview("IMG_ok.jpg").status, 200);
}

TEST_F(WebEngineTest, APhotoLargerThanTheCamerasIs422) {
  WritePhoto(photos_.Path("IMG_large.jpg"), TextureJpeg(640, 480), 0);
  Start(320, 240);
  ExpectNotRefocusable("IMG_large.jpg");
}

TEST_F(WebEngineTest, AHugeOriginalIs422) {
  WritePhoto(photos_.Path("IMG_huge.jpg"), FlatJpeg(9000, 9000), 0);
  Start(1280, 960);  // room for the file: the original is what is too large
  ExpectNotRefocusable("IMG_huge.jpg");
}

TEST_F(WebEngineTest, ExtendedXmpInManyPiecesIs422) {
  WritePhoto(photos_.Path("IMG_pieces.jpg"), TextureJpeg(640, 480), 661);
  Start(640, 480);
  ExpectNotRefocusable("IMG_pieces.jpg");
}

TEST_F(WebEngineTest, AnswersNameThePhotoNotItsPath) {
  const std::vector<uint8_t> plain = TextureJpeg(320, 240);
  std::ofstream(photos_.Path("plain.jpg"), std::ios::binary)
      .write(reinterpret_cast<const char*>(plain.data()),
             static_cast<std::streamsize>(plain.size()));
  Start(640, 480);
  ExpectNotRefocusable("plain.jpg");
  EXPECT_NE(log_sink_.all().find(photos_.Path("plain.jpg")), std::string::npos)
      << "the journal keeps the path: " << log_sink_.all();
}

TEST_F(WebEngineTest, AMissingFolderIsNotNamedToTheClient) {
  photo_dir_ = photos_.Path("card");
  Start(640, 480);
  HttpResponse r = Http(server_->port(), "GET", "/api/photos", kAuth);
  EXPECT_EQ(r.status, 404);
  EXPECT_EQ(r.body.find(photos_.dir()), std::string::npos) << r.body;
  EXPECT_NE(r.body.find("photo folder"), std::string::npos) << r.body;
  r = Preview("IMG_1.jpg");
  EXPECT_EQ(r.status, 404);
  EXPECT_EQ(r.body.find(photos_.dir()), std::string::npos) << r.body;
  EXPECT_NE(log_sink_.all().find(photo_dir_), std::string::npos) << log_sink_.all();
}

}  // namespace
}  // namespace lb
