#include "firmware/codecs/codec_decoder.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdlib>
#include <string>

#include "tests/firmware/codecs/recording_sink.h"
#include "tests/firmware/codecs/test_images.h"

namespace lb {
namespace {

// The codecs as the file sensor sees them: header, pixels and tags of one file.
TEST(CodecDecoderTest, ProbesStreamsAndTagsAFile) {
  char dir[] = "/tmp/codec_decoder_testXXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string path = std::string(dir) + "/a.pgm";
  const std::vector<uint16_t> samples = {0, 50, 100, 150, 200, 250};
  ASSERT_TRUE(test::WriteFile(path, test::EncodePnm("P5", 3, 2, 255, samples)));

  const ImageDecoder& decoder = CodecImageDecoder();
  ImageHeader header;
  ASSERT_TRUE(decoder.Probe(path.c_str(), &header).ok());
  EXPECT_EQ(header.format, PixelFormat::kGray8);
  EXPECT_EQ(header.width, 3);
  EXPECT_EQ(header.height, 2);
  test::RecordingSink sink;
  ASSERT_TRUE(decoder.Stream(path.c_str(), 4, sink).ok()) << sink.error;
  ASSERT_EQ(sink.frames.size(), 1u);
  EXPECT_EQ(sink.frames[0].info.index, 4);
  EXPECT_EQ(sink.frames[0].pixels, std::vector<uint8_t>(samples.begin(), samples.end()));
  const CameraTags tags = decoder.Tags(path.c_str(), 3, 2);  // a PGM has no EXIF
  EXPECT_EQ(tags.focal_px, 0);
  EXPECT_EQ(tags.orientation, 0);

  const Status missing = decoder.Probe((std::string(dir) + "/b.pgm").c_str(), &header);
  EXPECT_EQ(missing.code(), Code::kNotFound);
  unlink(path.c_str());
  rmdir(dir);
}

}  // namespace
}  // namespace lb
