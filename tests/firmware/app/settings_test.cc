// The shared settings table: each setting takes the ends of its range and refuses one step past
// them, numbers never wrap, and the spellings the command line and refocusd.conf use find the
// same setting.
#include "firmware/app/settings.h"

#include <gtest/gtest.h>

#include <string>

namespace lb {
namespace {

bool Parse(const char* name, const char* text, JobOptions* job, std::string* why = nullptr) {
  const Setting* s = FindSetting(name);
  EXPECT_NE(s, nullptr) << name;
  std::string ignored;
  return s != nullptr && s->parse(text, job, why ? why : &ignored);
}

TEST(Settings, EachTakesItsRangeAndNothingPastIt) {
  struct Case {
    const char* name;
    const char* lowest;
    const char* below;
    const char* highest;
    const char* above;
  };
  for (const Case& c : {
           Case{"f-number", "1", "0.99", "22", "22.01"},
           Case{"aperture-rotation", "-360", "-360.5", "360", "360.5"},
           Case{"blade-curvature", "0", "-0.01", "1", "1.01"},
           Case{"highlight-threshold", "0", "-1", "255", "256"},
           Case{"highlight-gain", "1", "0.99", "8", "8.01"},
           Case{"max-blur-radius", "0", "-1", "128", "129"},
           Case{"quality", "1", "0", "100", "101"},
           Case{"frames", "2", "1", "16", "17"},
           Case{"labels", "2", "1", "256", "257"},
           Case{"focal-35mm", "8", "7", "2000", "2001"},
           Case{"resolution", "16x16", "15x16", "8192x8192", "8192x8193"},
           Case{"working-size", "16x16", "16x15", "8192x8192", "8193x8192"},
       }) {
    SCOPED_TRACE(c.name);
    JobOptions job;
    EXPECT_TRUE(Parse(c.name, c.lowest, &job));
    EXPECT_TRUE(Parse(c.name, c.highest, &job));
    std::string why;
    EXPECT_FALSE(Parse(c.name, c.below, &job, &why));
    EXPECT_NE(why.find(c.below), std::string::npos) << why;
    EXPECT_FALSE(Parse(c.name, c.above, &job));
  }
}

TEST(Settings, NumbersNeverWrap) {
  JobOptions job;
  const JobOptions before = job;
  for (const char* size : {"4294967616x240", "320x4294967536", "99999999999x1", "-320x240"}) {
    EXPECT_FALSE(Parse("resolution", size, &job)) << size;
    EXPECT_FALSE(Parse("working-size", size, &job)) << size;
  }
  EXPECT_FALSE(Parse("quality", "4294967388", &job));  // 92 + 2^32
  EXPECT_FALSE(Parse("focus", "4294967306,10", &job));
  EXPECT_FALSE(Parse("f-number", "1e40", &job));
  EXPECT_FALSE(Parse("f-number", "nan", &job));
  EXPECT_EQ(job.sensor.width, before.sensor.width);
  EXPECT_EQ(job.quality, before.quality);
  EXPECT_EQ(job.render.focus.width, before.render.focus.width);
}

TEST(Settings, ANumberTooSmallForAFloatIsInRangeWhereZeroIs) {
  JobOptions job;
  job.render.aperture.curvature = 0.5f;
  std::string why;
  EXPECT_TRUE(Parse("blade-curvature", "1e-40", &job, &why)) << why;
  EXPECT_GE(job.render.aperture.curvature, 0.0f);
  EXPECT_LT(job.render.aperture.curvature, 1e-30f);
  EXPECT_TRUE(Parse("blade-curvature", "1e-400", &job, &why)) << why;
  // Where the range starts above zero, the tiny number is below it, as any other.
  EXPECT_FALSE(Parse("f-number", "1e-40", &job, &why));
  EXPECT_NE(why.find("'1e-40' is not a number from 1 to 22"), std::string::npos) << why;
  EXPECT_FALSE(Parse("blade-curvature", "-1e-40", &job));
}

TEST(Settings, BothSpellingsAndTheOlderNamesFindOneSetting) {
  EXPECT_EQ(FindSetting("f_number"), FindSetting("f-number"));
  EXPECT_EQ(FindSetting("max_blur_radius"), FindSetting("max-radius"));
  EXPECT_EQ(FindSetting("size"), FindSetting("resolution"));
  EXPECT_EQ(FindSetting("rotation"), FindSetting("aperture_rotation"));
  EXPECT_EQ(FindSetting("curvature"), FindSetting("blade-curvature"));
  EXPECT_EQ(FindSetting("f-numbe"), nullptr);
  EXPECT_EQ(FindSetting("f-number-"), nullptr);
  for (int i = 0; const Setting* s = SettingAt(i); ++i) EXPECT_EQ(FindSetting(s->name), s);
}

TEST(Settings, AFocusPointMeansOneThingInEitherSpelling) {
  JobOptions a, b;
  ASSERT_TRUE(Parse("focus", "100,80", &a));
  ASSERT_TRUE(Parse("focus", "point 100,80", &b));
  EXPECT_EQ(a.render.focus.x, b.render.focus.x);
  EXPECT_EQ(a.render.focus.width, b.render.focus.width);
  EXPECT_GT(a.render.focus.width, 1) << "a point is a small square, not one pixel";
  EXPECT_LE(a.render.focus.x, 100);
  EXPECT_GT(a.render.focus.x + a.render.focus.width, 100);
  ASSERT_TRUE(Parse("focus", "10,20,30,40", &a));
  ASSERT_TRUE(Parse("focus", "region 10,20,30,40", &b));
  EXPECT_EQ(a.render.focus.x, 10);
  EXPECT_EQ(b.render.focus.height, 40);
  ASSERT_TRUE(Parse("focus", "center", &a));
  EXPECT_EQ(a.render.focus.width, 0);
  for (const char* bad : {"10", "10,20,30", "10,20,30,0", "point 10,20,30,40", "region 10,20",
                          "10,20,", "-5,10", "10, 20", ""}) {
    EXPECT_FALSE(Parse("focus", bad, &a)) << bad;
  }
}

TEST(Settings, ApertureShapes) {
  JobOptions a, b;
  ASSERT_TRUE(Parse("aperture", "6-blade", &a));
  ASSERT_TRUE(Parse("aperture", "polygon:6", &b));
  EXPECT_EQ(a.render.aperture.blades, 6);
  EXPECT_EQ(b.render.aperture.blades, 6);
  ASSERT_TRUE(Parse("aperture", "disc", &a));
  EXPECT_EQ(a.render.aperture.blades, 0);
  for (const char* bad : {"2-blade", "13-blade", "polygon:6-blade", "6-blades", "6", "polygon:"}) {
    EXPECT_FALSE(Parse("aperture", bad, &a)) << bad;
  }
}

TEST(Settings, UnknownFocalLengthIsZero) {
  JobOptions job;
  job.focal_35mm = 50;
  ASSERT_TRUE(Parse("focal-35mm", "0", &job));
  EXPECT_EQ(job.focal_35mm, 0);
  ASSERT_TRUE(Parse("resolution", "native", &job));
  EXPECT_EQ(job.sensor.width, 0);
}

TEST(Settings, HelpNamesEverySettingOfItsGroup) {
  for (const SettingGroup g : {SettingGroup::kLens, SettingGroup::kBurst, SettingGroup::kDepth}) {
    const std::string help = SettingsHelp(g);
    for (int i = 0; const Setting* s = SettingAt(i); ++i) {
      const bool listed = help.find(std::string("--") + s->name + " ") != std::string::npos;
      EXPECT_EQ(listed, s->group == g) << s->name;
    }
  }
}

}  // namespace
}  // namespace lb
