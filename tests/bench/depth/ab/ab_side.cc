// One side of the A/B (ab_side.h): built with AB_REFERENCE against the other revision's algo/.
#include "tests/bench/depth/ab/ab_side.h"

#include <chrono>
#include <memory>
#include <vector>

#include "algo/depth/depth_stage.h"

#ifdef AB_REFERENCE
#define AB_MAKE AbMakeReference
#define AB_RUN AbRunReference
#else
#define AB_MAKE AbMakeCurrent
#define AB_RUN AbRunCurrent
#endif

namespace {

struct Side {
  lb::DepthConfig config;
  std::vector<uint8_t> memory;
  lb::DepthStage stage;
  std::vector<lb::ConstImageU8> views;
  std::vector<lb::PlaneHomography> planes;
};

}  // namespace

void* AB_MAKE(const AbScene& scene) {
  auto side = std::make_unique<Side>();
  lb::DepthConfig& c = side->config;
  c.width = scene.width;
  c.height = scene.height;
  c.views = scene.views;
  c.reference = scene.reference;
  c.labels = scene.labels;
  c.disp_min_q8 = scene.disp_min_q8;
  c.disp_max_q8 = scene.disp_max_q8;
  c.geometry = scene.known_poses ? lb::ViewGeometry::kKnownPoses : lb::ViewGeometry::kRectified;
  c.subpixel = scene.subpixel;
  const size_t bytes = lb::DepthStage::RequiredBytes(c);
  side->memory.assign(bytes + lb::Arena::kAlign, 0);
  lb::Arena arena(lb::Arena::AlignUp(side->memory.data()), bytes);
  if (!side->stage.Configure(c, arena).ok()) return nullptr;
  for (int32_t v = 0; v < scene.views; ++v) {
    side->views.push_back(lb::MakeView(scene.pixels[v], scene.width, scene.height, 3));
  }
  if (scene.known_poses) {
    side->planes.resize(static_cast<size_t>(scene.views) * scene.labels);
    for (size_t i = 0; i < side->planes.size(); ++i) {
      for (int k = 0; k < 9; ++k) side->planes[i].m[k] = scene.planes[9 * i + k];
    }
  }
  return side.release();
}

double AB_RUN(void* p, uint16_t* disp) {
  Side* side = static_cast<Side*>(p);
  const lb::DepthConfig& c = side->config;
  const auto t0 = std::chrono::steady_clock::now();
  if (!side->planes.empty() && !side->stage.SetPlanes(side->planes.data()).ok()) return -1;
  if (!side->stage.Compute(side->views.data(), lb::MakeView(disp, c.width, c.height)).ok()) {
    return -1;
  }
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
