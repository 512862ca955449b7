#include "tests/algo/depth/hci.h"

#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/codecs/image_file.h"
#include "tests/algo/depth/fit_score.h"

namespace lb::hci {
namespace {

// The benchmark's float map: "Pf", width height, scale (negative: little-endian), rows bottom
// to top.
Status ReadPfm(const std::string& path, int32_t width, int32_t height, std::vector<float>* out) {
  FILE* f = fopen(path.c_str(), "rb");
  if (!f) return Status(Code::kNotFound, "%s: cannot open", path.c_str());
  char magic[3] = {};
  int w = 0, h = 0;
  double scale = 0;
  const bool header = fscanf(f, "%2s %d %d %lf", magic, &w, &h, &scale) == 4 && fgetc(f) != EOF;
  if (!header || strcmp(magic, "Pf") != 0 || w != width || h != height || !(scale < 0)) {
    fclose(f);
    return Status(Code::kCorruptData, "%s: not a %dx%d little-endian grey PFM", path.c_str(), width,
                  height);
  }
  out->assign(static_cast<size_t>(w) * h, 0);
  for (int32_t y = h - 1; y >= 0; --y) {
    if (fread(out->data() + static_cast<size_t>(y) * w, 4, w, f) != static_cast<size_t>(w)) {
      fclose(f);
      return Status(Code::kCorruptData, "%s: short", path.c_str());
    }
  }
  fclose(f);
  return Status::Ok();
}

}  // namespace

const char* LayoutName(Layout layout) {
  switch (layout) {
    case Layout::kRow5:
      return "row5";
    case Layout::kRow9:
      return "row9";
    case Layout::kColumn9:
      return "column9";
    case Layout::kCross5:
      return "cross5";
  }
  return "?";
}

std::vector<ConstImageU8> Burst::Views() const {
  std::vector<ConstImageU8> out;
  for (const auto& v : views) out.push_back(MakeView(v.data(), width, height, 3));
  return out;
}

std::string DataDir() {
  const char* root = std::getenv("LB_SOURCE_DIR");
  const std::string dir = std::string(root ? root : ".") + "/../shared/data/hci/antinous";
  struct stat st;
  return stat(dir.c_str(), &st) == 0 && S_ISDIR(st.st_mode) ? dir : std::string();
}

Status Load(const std::string& dir, Layout layout, Burst* b) {
  *b = Burst{};
  // Grid offsets (column, row) from the centre camera (4, 4), in capture order.
  std::vector<std::pair<int32_t, int32_t>> grid;
  if (layout == Layout::kRow5 || layout == Layout::kRow9) {
    const int32_t half = layout == Layout::kRow5 ? 2 : 4;
    for (int32_t c = -half; c <= half; ++c) grid.push_back({c, 0});
  } else if (layout == Layout::kColumn9) {
    for (int32_t r = -4; r <= 4; ++r) grid.push_back({0, r});
  } else {
    grid = {{0, -1}, {-1, 0}, {0, 0}, {1, 0}, {0, 1}};
  }
  for (size_t i = 0; i < grid.size(); ++i) {
    if (grid[i].first == 0 && grid[i].second == 0) b->reference = static_cast<int32_t>(i);
    const int32_t cam = 9 * (grid[i].second + 4) + grid[i].first + 4;
    char name[64];
    snprintf(name, sizeof(name), "/input_Cam%03d.png", cam);
    ImageFileInfo info;
    std::vector<uint8_t> pixels;
    LB_RETURN_IF_ERROR(ReadImageFile((dir + name).c_str(), &info, &pixels));
    if (info.format != PixelFormat::kRgb8 || (b->width && info.width != b->width)) {
      return Status(Code::kCorruptData, "%s%s: not an RGB8 view like the others", dir.c_str(),
                    name);
    }
    b->width = info.width;
    b->height = info.height;
    b->views.push_back(std::move(pixels));
    b->dc.push_back(grid[i].first);
    b->dr.push_back(grid[i].second);
  }
  return ReadPfm(dir + "/gt_disp_lowres.pfm", b->width, b->height, &b->truth);
}

double FittedBadPixPercent(const Burst& b, const std::vector<float>& e, double threshold,
                           int32_t border, double* scale_out, double* offset_out) {
  return FittedBadPercent(b.truth, e, b.width, b.height, threshold, border, scale_out, offset_out);
}

}  // namespace lb::hci
