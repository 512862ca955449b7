// An independent reader (exiftool) finds the refocusable fields in what `refocus run` writes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "firmware/app/job.h"
#include "sim/synthetic/synthetic_sensor.h"
#include "tests/support/remove_tree.h"

namespace lb {
namespace {

std::string Capture(const std::string& cmd) {
  std::string out;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char buf[4096];
    for (size_t n; (n = fread(buf, 1, sizeof(buf), p)) > 0;) out.append(buf, n);
    pclose(p);
  }
  return out;
}

TEST(RefocusableExiftool, ReadsGDepthGImageAndGFocus) {
  if (system("exiftool -ver >/dev/null 2>&1") != 0) GTEST_SKIP() << "exiftool is not installed";
  char tmpl[] = "/tmp/refocusable-exif-XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const std::string path = std::string(tmpl) + "/photo.jpg";
  SyntheticSensor sensor;
  JobOptions o;
  o.sensor.width = 320;  // large enough that the XMP spills into extended XMP
  o.sensor.height = 240;
  o.pipeline.labels = 16;
  o.render.f_number = 2.0f;
  Job job;
  ASSERT_TRUE(job.Configure(&sensor, o).ok());
  Status s = job.Run(path.c_str(), nullptr);
  ASSERT_TRUE(s.ok()) << s.message();

  const std::string tags = Capture("exiftool -s -G1 -XMP:all '" + path + "'");
  for (const char* want : {"GDepth:Format", "GDepth:Near", "GDepth:Far", "GDepth:Mime",
                           "GDepth:DepthImage", "GImage:ImageData", "GFocus:BlurAtInfinity",
                           "GFocus:FocalDistance", "GFocus:FocalPointX", "GFocus:FocalPointY"}) {
    const std::string group =
        std::string("[XMP-") + std::string(want).substr(0, std::string(want).find(':')) + "]";
    const std::string name = std::string(want).substr(std::string(want).find(':') + 1);
    EXPECT_NE(tags.find(group), std::string::npos) << want << "\n" << tags;
    EXPECT_NE(tags.find(" " + name + " "), std::string::npos) << want << "\n" << tags;
  }
  EXPECT_NE(tags.find("RangeInverse"), std::string::npos) << tags;
  // The embedded depth image and original decode as what they claim to be.
  const std::string depth =
      Capture("exiftool -b -XMP-GDepth:DepthImage '" + path + "' | head -c 8 | od -An -tx1");
  EXPECT_NE(depth.find("89 50 4e 47"), std::string::npos) << depth;  // PNG signature
  const std::string image =
      Capture("exiftool -b -XMP-GImage:ImageData '" + path + "' | head -c 2 | od -An -tx1");
  EXPECT_NE(image.find("ff d8"), std::string::npos) << image;  // JPEG SOI
  (void)lb::test::RemoveTree(tmpl);
}

}  // namespace
}  // namespace lb
