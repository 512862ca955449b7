#include "firmware/refocusable/base64.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

namespace lb {
namespace {

std::string Encode(const std::string& s) {
  std::string out;
  Base64Encode(reinterpret_cast<const uint8_t*>(s.data()), s.size(), &out);
  return out;
}

std::string Decode(const std::string& s, Status* status) {
  std::vector<uint8_t> out;
  *status = Base64Decode(s.data(), s.size(), &out);
  return std::string(out.begin(), out.end());
}

// RFC 4648 section 10.
TEST(Base64Test, RfcVectors) {
  const char* pairs[][2] = {{"", ""},
                            {"f", "Zg=="},
                            {"fo", "Zm8="},
                            {"foo", "Zm9v"},
                            {"foob", "Zm9vYg=="},
                            {"fooba", "Zm9vYmE="},
                            {"foobar", "Zm9vYmFy"}};
  for (const auto& p : pairs) {
    EXPECT_EQ(Encode(p[0]), p[1]);
    Status status;
    EXPECT_EQ(Decode(p[1], &status), p[0]);
    EXPECT_TRUE(status.ok()) << status.message();
  }
}

TEST(Base64Test, AllByteValuesRoundTripAndWhitespaceIsSkipped) {
  std::string bytes;
  for (int i = 0; i < 256; ++i) bytes.push_back(static_cast<char>(i));
  std::string text = Encode(bytes);
  text.insert(10, "\n  ");
  text.insert(50, "\r\n\t");
  Status status;
  EXPECT_EQ(Decode(text, &status), bytes);
  EXPECT_TRUE(status.ok()) << status.message();
}

// Into the caller's buffer: exactly the bytes, and a buffer the text might overflow refused
// before a byte is written.
TEST(Base64Test, IntoAFixedBufferChecksItsCapacityFirst) {
  uint8_t out[7] = {0, 0, 0, 0, 0, 0, 0xAA};
  size_t written = 99;
  Status status = Base64DecodeInto("Zm9v YmE=", 9, out, 6, &written);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(out), written), "fooba");
  EXPECT_EQ(out[6], 0xAA);
  memset(out, 0, sizeof(out));
  status = Base64DecodeInto("Zm9vYmFy", 8, out, 5, &written);
  EXPECT_EQ(status.code(), Code::kOutOfMemory) << status.message();
  EXPECT_EQ(written, 0u);
  EXPECT_EQ(out[0], 0);
}

TEST(Base64Test, GarbageIsAnErrorNamingTheProblem) {
  for (const char* bad :
       {"Zm9v!", "Zg=", "Z", "Zg==Zg==", "=Zg=", "Zm9vY", "Zm9=v", "Zg===", "Zm9v\x80"}) {
    Status status;
    Decode(bad, &status);
    EXPECT_FALSE(status.ok()) << bad;
    EXPECT_EQ(status.code(), Code::kCorruptData);
    EXPECT_EQ(std::string(status.message()).rfind("base64: ", 0), 0u) << status.message();
  }
}

TEST(Base64Test, Md5HexMatchesRfc1321) {
  char hex[33];
  Md5Hex(nullptr, 0, hex);
  EXPECT_STREQ(hex, "D41D8CD98F00B204E9800998ECF8427E");
  Md5Hex(reinterpret_cast<const uint8_t*>("abc"), 3, hex);
  EXPECT_STREQ(hex, "900150983CD24FB0D6963F7D28E17F72");
  const char* quick = "The quick brown fox jumps over the lazy dog";
  Md5Hex(reinterpret_cast<const uint8_t*>(quick), strlen(quick), hex);
  EXPECT_STREQ(hex, "9E107D9D372BB6826BD81D3542A419D6");
}

}  // namespace
}  // namespace lb
