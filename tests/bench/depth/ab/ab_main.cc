// In-process A/B of the depth stage: this revision against another one built beside it
// (scripts/ab_depth.sh), one compute of each by turns on teddy (rectified shifts, 64 labels)
// and on a synthetic handheld burst (640x480, 7 views: the plane sweep, then the rectified shifts
// over the same labels, the two sides of depth_bench's PlanesOverRectified). A busy host slows both
// sides of a turn alike, so the median of the per-turn ratios shows changes too small for
// separate benchmark runs to tell apart. Prints each side's median time, that ratio and whether the
// maps are the same bit for bit.
//   ab_depth [turns [scene]]   (scene: teddy, handheld or handheld-r alone, e.g. under callgrind)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "algo/depth/depth_stage.h"
#include "tests/algo/depth/handheld.h"
#include "tests/algo/depth/middlebury.h"
#include "tests/bench/depth/ab/ab_side.h"

namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

const char* g_only = nullptr;  // the one scene to run, or nullptr for all

// Returns false when either side refuses the scene or a compute fails.
bool Compare(const char* name, const AbScene& scene, int turns) {
  if (g_only != nullptr && std::string(g_only) != name) return true;
  void* current = AbMakeCurrent(scene);
  void* reference = AbMakeReference(scene);
  if (current == nullptr || reference == nullptr) {
    fprintf(stderr, "%s: a side refused the scene\n", name);
    return false;
  }
  const size_t n = static_cast<size_t>(scene.width) * scene.height;
  std::vector<uint16_t> a(n), b(n);
  std::vector<double> ta, tb, ratio;
  bool same = true;
  for (int i = 0; i < turns; ++i) {
    double x = 0, y = 0;
    if (i % 2 == 0) {
      x = AbRunCurrent(current, a.data());
      y = AbRunReference(reference, b.data());
    } else {
      y = AbRunReference(reference, b.data());
      x = AbRunCurrent(current, a.data());
    }
    if (x < 0 || y < 0) {
      fprintf(stderr, "%s: a compute failed\n", name);
      return false;
    }
    ta.push_back(x);
    tb.push_back(y);
    ratio.push_back(x / y);
    same = same && a == b;
  }
  printf("%-10s current %7.2f ms  reference %7.2f ms  current/reference %.4f  maps %s\n", name,
         Median(ta), Median(tb), Median(ratio), same ? "the same" : "DIFFER");
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const int turns = argc > 1 ? atoi(argv[1]) : 100;
  if (turns < 1) return 2;
  g_only = argc > 2 ? argv[2] : nullptr;
  bool ok = true;
  lb::middlebury::Set teddy;
  const std::string dir = lb::middlebury::DataDir();
  if (!dir.empty() && lb::middlebury::Load(dir, "teddy", &teddy).ok()) {
    std::vector<const uint8_t*> pixels;
    for (const auto& v : teddy.views) pixels.push_back(v.data());
    AbScene s;
    s.width = teddy.width;
    s.height = teddy.height;
    s.views = static_cast<int32_t>(pixels.size());
    s.reference = teddy.reference;
    s.labels = 64;
    s.disp_max_q8 = 63 * 64;  // as depth_bench's teddy
    s.pixels = pixels.data();
    ok = Compare("teddy", s, turns) && ok;
  } else {
    printf("teddy      skipped: ../shared/data/middlebury/teddy is absent\n");
  }
  lb::motiontest::Burst burst;
  if (lb::motiontest::MakeBurst(lb::motiontest::Handheld(1), 640, 480, 7, &burst)) {
    const lb::handheld::Labels l = lb::handheld::HandheldLabels(burst, 0.1);
    const std::vector<lb::PlaneHomography> planes = lb::handheld::Planes(burst, l);
    std::vector<int64_t> m;
    for (const auto& h : planes) m.insert(m.end(), h.m, h.m + 9);
    // Tightly packed, as AbScene wants them.
    std::vector<std::vector<uint8_t>> tight;
    std::vector<const uint8_t*> pixels;
    for (const auto& v : burst.views) {
      std::vector<uint8_t>& t = tight.emplace_back(static_cast<size_t>(v.width) * 3 * v.height);
      for (int32_t y = 0; y < v.height; ++y) {
        std::copy(v.Row(y), v.Row(y) + 3 * v.width,
                  t.begin() + static_cast<ptrdiff_t>(y) * 3 * v.width);
      }
      pixels.push_back(t.data());
    }
    AbScene s;
    s.width = l.config.width;
    s.height = l.config.height;
    s.views = l.config.views;
    s.reference = l.config.reference;
    s.labels = l.config.labels;
    s.disp_min_q8 = l.config.disp_min_q8;
    s.disp_max_q8 = l.config.disp_max_q8;
    s.known_poses = true;
    s.pixels = pixels.data();
    s.planes = m.data();
    ok = Compare("handheld", s, turns) && ok;
    // The same views and labels as rectified shifts: the other side of the plane sweep's bound.
    s.known_poses = false;
    s.planes = nullptr;
    ok = Compare("handheld-r", s, turns) && ok;
  }
  return ok ? 0 : 1;
}
