// The same views in three orders, the same reference view: first in the list, in the middle
// (as many views before it as after, give or take one), and last, the other views keeping their
// given order. Through the product's default path (motion with nothing said about the lens, the
// label plan from the points, the plane sweep, the occlusions' word on which end is near), each
// order must give the same decision (processed or refused, and why) and maps within 1.2x of each
// other in bad pixels after the scale and offset of inverse depth small motion cannot know
// (fit_score.h). Every Middlebury set (bad: off by more than 1 px in the units of the evaluated
// pair, on the nonocc mask) and every HCI layout (BadPix 0.3, 16 px border) we have.
// Label data: skips without ../shared/data/hci or ../shared/data/middlebury.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "algo/depth/depth_order.h"
#include "algo/depth/depth_stage.h"
#include "algo/motion/motion_stage.h"
#include "algo/pipeline/auto_geometry.h"
#include "tests/algo/depth/fit_score.h"
#include "tests/algo/depth/hci.h"
#include "tests/algo/depth/middlebury.h"
#include "tests/algo/pipeline/pipeline_depth.h"

namespace lb {
namespace {

constexpr int32_t kLabels = 64;
constexpr double kMaxRatio = 1.2;

struct Memory {
  std::vector<uint8_t> bytes;
  Arena Make(size_t n) {
    bytes.assign(n + Arena::kAlign, 0);
    return Arena(Arena::AlignUp(bytes.data()), n);
  }
};

// A scene as the test scores it: the views in their given order and the reference's truth.
struct Scene {
  int32_t width = 0, height = 0, reference = 0;
  std::vector<ConstImageU8> views;
  std::vector<float> truth;   // px per view step
  std::vector<uint8_t> mask;  // 1: scored
  double threshold = 0;       // px per view step
  int32_t border = 0;
};

// The product's default path on `views` (the reference at `reference`): signed disparities in
// the plan's unit, or the status that refused the burst.
Status AutoDepth(const Scene& s, const std::vector<ConstImageU8>& views, int32_t reference,
                 std::vector<float>* out) {
  MotionConfig mc;
  mc.width = s.width;
  mc.height = s.height;
  mc.views = static_cast<int32_t>(views.size());
  mc.estimate_focal = true;  // as the product does when nothing told the lens
  Memory motion_memory;
  Arena motion_arena = motion_memory.Make(MotionStage::RequiredBytes(mc));
  MotionStage motion;
  LB_RETURN_IF_ERROR(motion.Configure(mc, motion_arena));
  MotionResult m;
  LB_RETURN_IF_ERROR(
      motion.Estimate(views.data(), reference, DefaultIntrinsics(s.width, s.height), &m));
  DepthConfig c;
  c.width = s.width;
  c.height = s.height;
  c.views = mc.views;
  c.reference = reference;
  c.labels = kLabels;
  c.subpixel = true;
  c.geometry = ViewGeometry::kKnownPoses;
  c.disp_max_q8 = 16 << 8;  // sizing only: the plan sets the burst's own
  Memory memory;
  Arena arena = memory.Make(DepthStage::RequiredBytes(c));
  DepthStage stage;
  LB_RETURN_IF_ERROR(stage.Configure(c, arena));
  std::vector<PlaneHomography> planes(static_cast<size_t>(c.views) * kLabels);
  LabelRange range;
  LB_RETURN_IF_ERROR(SetDepthGeometry(m, false, &stage, planes.data(), &range));
  std::vector<uint16_t> map(static_cast<size_t>(c.width) * c.height);
  const ImageU16 image = MakeView(map.data(), c.width, c.height);
  LB_RETURN_IF_ERROR(stage.Compute(views.data(), image));
  std::vector<uint8_t> scratch(DepthOrderScratchBytes(c.width, c.height));
  LB_RETURN_IF_ERROR(
      OrderDepth(views.data(), planes.data(), scratch.data(), &stage, &motion, &m, image, nullptr));
  TrimAsThePipelineDoes(views[static_cast<size_t>(reference)], image, stage.config());
  const int32_t bias = DepthStage::MapBiasQ8(stage.config());
  out->resize(map.size());
  for (size_t i = 0; i < map.size(); ++i) (*out)[i] = static_cast<float>(map[i] - bias) / 256.0f;
  return Status::Ok();
}

// Loads a scene by name: "hci-<layout>" or a Middlebury set's name. `absent`: no data folder.
bool LoadScene(const std::string& name, Scene* s, hci::Burst* burst, middlebury::Set* set,
               std::string* why, bool* absent) {
  *absent = false;
  if (name.rfind("hci-", 0) == 0) {
    const std::string dir = hci::DataDir();
    if (dir.empty()) {
      *why = "../shared/data/hci/antinous is absent: nothing to measure";
      *absent = true;
      return false;
    }
    const std::string layout = name.substr(4);
    hci::Layout l = hci::Layout::kRow5;
    for (const hci::Layout k :
         {hci::Layout::kRow5, hci::Layout::kRow9, hci::Layout::kColumn9, hci::Layout::kCross5}) {
      if (layout == hci::LayoutName(k)) l = k;
    }
    if (!hci::Load(dir, l, burst).ok()) {
      *why = "cannot read " + dir;
      return false;
    }
    s->width = burst->width;
    s->height = burst->height;
    s->reference = burst->reference;
    s->views = burst->Views();
    s->truth = burst->truth;
    s->mask.assign(s->truth.size(), 1);
    s->threshold = 0.3;
    s->border = 16;
    return true;
  }
  const std::string dir = middlebury::DataDir();
  if (dir.empty()) {
    *why = "../shared/data/middlebury is absent: nothing to measure";
    *absent = true;
    return false;
  }
  if (!middlebury::Load(dir, name, set).ok()) {
    *why = "cannot read " + dir + "/" + name;
    return false;
  }
  s->width = set->width;
  s->height = set->height;
  s->reference = set->reference;
  s->views = set->Views();
  s->truth = set->truth;
  s->mask.resize(s->truth.size());
  for (size_t i = 0; i < s->mask.size(); ++i) s->mask[i] = set->mask[i] == 255 && set->truth[i] > 0;
  s->threshold = 1.0 / set->eval_steps;
  s->border = 0;
  return true;
}

class ViewOrder : public ::testing::TestWithParam<const char*> {};

TEST_P(ViewOrder, GivesTheSameDecisionAndMapWhereverTheReferenceIsListed) {
  Scene s;
  hci::Burst burst;
  middlebury::Set set;
  std::string why;
  bool absent = false;
  if (!LoadScene(GetParam(), &s, &burst, &set, &why, &absent)) {
    if (absent) GTEST_SKIP() << why;
    FAIL() << why;
  }
  std::vector<ConstImageU8> others;
  for (int32_t v = 0; v < static_cast<int32_t>(s.views.size()); ++v) {
    if (v != s.reference) others.push_back(s.views[v]);
  }
  const int32_t n = static_cast<int32_t>(others.size());
  const char* names[3] = {"first", "middle", "last"};
  const int32_t at[3] = {0, n / 2, n};
  Status status[3];
  double bad[3] = {};
  for (int32_t k = 0; k < 3; ++k) {
    std::vector<ConstImageU8> views = others;
    views.insert(views.begin() + at[k], s.views[s.reference]);
    std::vector<float> est;
    status[k] = AutoDepth(s, views, at[k], &est);
    if (!status[k].ok()) {
      printf("%s, reference %s: refused: %s\n", GetParam(), names[k], status[k].message());
      continue;
    }
    double a = 0, c = 0;
    bad[k] =
        FittedBadPercent(s.truth, est, s.width, s.height, s.threshold, s.border, &a, &c, &s.mask);
    printf("%s, reference %s: bad %.2f %% (fit %.3f x + %.3f)\n", GetParam(), names[k], bad[k], a,
           c);
  }
  for (int32_t k = 1; k < 3; ++k) {
    EXPECT_EQ(status[k].code(), status[0].code())
        << names[k] << ": " << status[k].message() << " / first: " << status[0].message();
  }
  if (!status[0].ok() || !status[1].ok() || !status[2].ok()) return;
  const double lo = std::min({bad[0], bad[1], bad[2]});
  const double hi = std::max({bad[0], bad[1], bad[2]});
  printf("%s: bad %.2f / %.2f / %.2f %% (first / middle / last), spread %.2fx\n", GetParam(),
         bad[0], bad[1], bad[2], lo > 0 ? hi / lo : 0.0);
  EXPECT_LE(hi, kMaxRatio * lo);
}

INSTANTIATE_TEST_SUITE_P(Sets, ViewOrder,
                         ::testing::Values("tsukuba", "venus", "teddy", "sawtooth", "barn1",
                                           "hci-row5", "hci-cross5", "hci-row9", "hci-column9"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           std::string name = info.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

}  // namespace
}  // namespace lb
