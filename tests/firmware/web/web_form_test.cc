// The page's form bodies as libmicrohttpd's post processor hands them over (a value may come in
// pieces), and the refocus choice read from them; the HTTP side is web_server_test.cc's.
#include "firmware/web/web_form.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>

namespace lb {
namespace {

bool Add(Fields* f, const char* key, const std::string& data, uint64_t offset = 0) {
  return f->Add(key, data.data(), offset, data.size());
}

TEST(WebForm, AValueInPiecesIsJoinedAndAStrayPieceRefused) {
  Fields f;
  ASSERT_TRUE(Add(&f, "name", "IMG_0001"));
  ASSERT_TRUE(Add(&f, "name", ".jpg", 8));
  EXPECT_STREQ(f.Get("name"), "IMG_0001.jpg");
  EXPECT_EQ(f.Get("x0"), nullptr);
  EXPECT_FALSE(Add(&f, "name", "x", 3)) << "a piece must continue where the value ends";
  EXPECT_FALSE(Add(&f, "x0", "5", 1)) << "a piece must continue the last field";
  EXPECT_STREQ(f.Get("name"), "IMG_0001.jpg");
}

TEST(WebForm, ADecodedNulAndTooManyFieldsAreRefused) {
  Fields f;
  EXPECT_FALSE(Add(&f, "name", std::string("a.jpg\0.png", 10)));
  for (int i = 0; i < Fields::kMax; ++i) {
    char key[8];
    snprintf(key, sizeof(key), "k%d", i);
    ASSERT_TRUE(Add(&f, key, "v"));
  }
  EXPECT_FALSE(Add(&f, "one_more", "v"));
}

Fields Body(const char* text) {  // "k=v&k=v", already decoded
  Fields f;
  std::string s = text;
  size_t start = 0;
  while (start <= s.size()) {
    size_t end = s.find('&', start);
    if (end == std::string::npos) end = s.size();
    const std::string pair = s.substr(start, end - start);
    const size_t eq = pair.find('=');
    EXPECT_NE(eq, std::string::npos) << pair;
    EXPECT_TRUE(Add(&f, pair.substr(0, eq).c_str(), pair.substr(eq + 1)));
    start = end + 1;
  }
  return f;
}

TEST(WebForm, ATapIsAPointAndADragIsPutInOrder) {
  std::string name;
  RefocusParams p;
  ASSERT_TRUE(ParseRefocus(Body("name=a.jpg&x0=0.25&y0=0.75"), &name, &p).ok());
  EXPECT_EQ(name, "a.jpg");
  EXPECT_FLOAT_EQ(p.x1, 0.25f);
  EXPECT_FLOAT_EQ(p.y1, 0.75f);
  ASSERT_TRUE(
      ParseRefocus(Body("name=a.jpg&x0=0.9&y0=0.8&x1=0.1&y1=0.2&f=5.6&blades=6"), &name, &p).ok());
  EXPECT_FLOAT_EQ(p.x0, 0.1f);
  EXPECT_FLOAT_EQ(p.x1, 0.9f);
  EXPECT_FLOAT_EQ(p.y0, 0.2f);
  EXPECT_FLOAT_EQ(p.y1, 0.8f);
  EXPECT_FLOAT_EQ(p.f_number, 5.6f);
  EXPECT_EQ(p.aperture.blades, 6);
}

TEST(WebForm, EachBadValueIsRefusedWithItsName) {
  const struct {
    const char *body, *names;
  } kBad[] = {
      {"x0=0.5&y0=0.5", "name="},
      {"name=a.jpg&x0=1.5&y0=0.5", "x0 and y0"},
      {"name=a.jpg&x0=0.5&y0=nan", "x0 and y0"},
      {"name=a.jpg&x0=0.5&y0=0.5x", "x0 and y0"},
      {"name=a.jpg&x0=0.5&y0=0.5&x1=-0.1", "x1 and y1"},
      {"name=a.jpg&x0=0.5&y0=0.5&f=0.5", "f must"},
      {"name=a.jpg&x0=0.5&y0=0.5&blades=2", "blades"},
      {"name=a.jpg&x0=0.5&y0=0.5&blades=4.5", "blades"},
      {"name=a.jpg&x0=0.5&y0=0.5&blades=13", "blades"},
  };
  for (const auto& bad : kBad) {
    std::string name;
    RefocusParams p;
    const Status s = ParseRefocus(Body(bad.body), &name, &p);
    EXPECT_EQ(s.code(), Code::kInvalidArgument) << bad.body;
    EXPECT_NE(strstr(s.message(), bad.names), nullptr) << bad.body << ": " << s.message();
  }
}

}  // namespace
}  // namespace lb
