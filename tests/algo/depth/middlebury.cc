#include "tests/algo/depth/middlebury.h"

#include <sys/stat.h>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <utility>

#include "firmware/codecs/image_file.h"

namespace lb::middlebury {

std::vector<ConstImageU8> Set::Views() const {
  std::vector<ConstImageU8> out;
  for (const auto& v : views) out.push_back(MakeView(v.data(), width, height, 3));
  return out;
}

std::string DataDir() {
  const char* root = std::getenv("LB_SOURCE_DIR");
  const std::string dir = std::string(root ? root : ".") + "/../shared/data/middlebury";
  struct stat st;
  return stat(dir.c_str(), &st) == 0 && S_ISDIR(st.st_mode) ? dir : std::string();
}

static Status ReadExpect(const std::string& path, PixelFormat format, const Set& set,
                         std::vector<uint8_t>* pixels) {
  ImageFileInfo info;
  LB_RETURN_IF_ERROR(ReadImageFile(path.c_str(), &info, pixels));
  if (info.format != format ||
      (set.width && (info.width != set.width || info.height != set.height))) {
    return Status(Code::kCorruptData, "%s: unexpected format or size %dx%d", path.c_str(),
                  info.width, info.height);
  }
  return Status::Ok();
}

Status Load(const std::string& dir, const std::string& name, Set* set) {
  *set = Set{};
  set->name = name;
  std::vector<std::string> views;
  std::string truth;
  float truth_scale = 1;
  if (name == "tsukuba") {
    for (int i = 1; i <= 5; ++i)
      views.push_back(dir + "/tsukuba/scene1.row3.col" + std::to_string(i) + ".ppm");
    truth = dir + "/tsukuba/truedisp.row3.col3.pgm";
    truth_scale = 1.0f / 16;  // px per view step
    set->eval_steps = 1;
  } else {
    for (int i = 0; i <= 8; ++i)
      views.push_back(dir + "/" + name + "/im" + std::to_string(i) + ".ppm");
    truth = dir + "/" + name + "/disp2.pgm";
    // im2-im6 is 4 steps: value / 8 for the 2001 sets, / 4 for teddy.
    truth_scale = name == "teddy" ? 1.0f / 16 : 1.0f / 32;
    set->eval_steps = 4;
  }
  set->reference = 2;
  for (const auto& path : views) {
    ImageFileInfo info;
    std::vector<uint8_t> pixels;
    LB_RETURN_IF_ERROR(ReadImageFile(path.c_str(), &info, &pixels));
    if (info.format != PixelFormat::kRgb8) {
      return Status(Code::kCorruptData, "%s: not RGB8", path.c_str());
    }
    if (set->width == 0) {
      set->width = info.width;
      set->height = info.height;
    } else if (info.width != set->width || info.height != set->height) {
      return Status(Code::kCorruptData, "%s: size differs from the first view", path.c_str());
    }
    set->views.push_back(std::move(pixels));
  }
  std::vector<uint8_t> pixels;
  LB_RETURN_IF_ERROR(ReadExpect(truth, PixelFormat::kGray8, *set, &pixels));
  for (uint8_t v : pixels) set->truth.push_back(v == 0 ? -1.0f : v * truth_scale);
  // The masks are palette PNGs: the reader may give grey or RGB; white (255) is evaluated.
  // sawtooth and barn1 have none here: every pixel with a known disparity counts.
  const std::string mask = dir + "/masks/" + name + "/nonocc.png";
  struct stat st;
  if (stat(mask.c_str(), &st) != 0) {
    set->mask.assign(set->truth.size(), 255);
    return Status::Ok();
  }
  ImageFileInfo info;
  LB_RETURN_IF_ERROR(ReadImageFile(mask.c_str(), &info, &pixels));
  const int channels = info.format == PixelFormat::kRgb8 ? 3 : 1;
  if ((info.format != PixelFormat::kGray8 && channels != 3) || info.width != set->width ||
      info.height != set->height) {
    return Status(Code::kCorruptData, "%s: unexpected format or size", mask.c_str());
  }
  for (size_t i = 0; i < pixels.size(); i += channels) set->mask.push_back(pixels[i]);
  return Status::Ok();
}

double BadPixelPercent(const Set& set, ConstImageU16 disp_q8) {
  int64_t bad = 0, total = 0;
  for (int32_t y = 0; y < set.height; ++y) {
    for (int32_t x = 0; x < set.width; ++x) {
      const size_t i = static_cast<size_t>(y) * set.width + x;
      if (set.mask[i] != 255 || set.truth[i] <= 0) continue;
      const float d = disp_q8.Row(y)[x] / 256.0f;
      ++total;
      if (std::fabs(d - set.truth[i]) * set.eval_steps > 1.0f) ++bad;
    }
  }
  return total ? 100.0 * static_cast<double>(bad) / static_cast<double>(total) : 100.0;
}

double BestScaleBadPixelPercent(const Set& set, ConstImageU16 disp_q8, double* best_scale) {
  // Pixel i is good for the scales s with |s d_i - t_i| e <= 1: an interval. The best scale is
  // where most intervals overlap: a sweep over their ends, starts before ends at a tie (closed).
  std::vector<std::pair<double, int>> ends;
  int64_t total = 0, always = 0;
  for (int32_t y = 0; y < set.height; ++y) {
    for (int32_t x = 0; x < set.width; ++x) {
      const size_t i = static_cast<size_t>(y) * set.width + x;
      if (set.mask[i] != 255 || set.truth[i] <= 0) continue;
      ++total;
      const double d = disp_q8.Row(y)[x] / 256.0, t = set.truth[i], tol = 1.0 / set.eval_steps;
      if (d <= 0) {
        always += t <= tol;
        continue;
      }
      ends.push_back({(t - tol) / d, -1});
      ends.push_back({(t + tol) / d, +1});
    }
  }
  std::sort(ends.begin(), ends.end());
  int64_t open = 0, best = 0;
  *best_scale = 1;
  for (size_t k = 0; k < ends.size(); ++k) {
    open -= ends[k].second;
    if (open > best) {
      best = open;
      *best_scale = k + 1 < ends.size() ? 0.5 * (ends[k].first + ends[k + 1].first) : ends[k].first;
    }
  }
  return total ? 100.0 * static_cast<double>(total - always - best) / static_cast<double>(total)
               : 100.0;
}

}  // namespace lb::middlebury
