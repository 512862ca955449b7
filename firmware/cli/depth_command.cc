// refocus depth: the views of a burst -> the reference view's disparity in px per view step as a
// PFM, and optionally a colour-mapped PNG preview. With --geometry auto (the default) the camera
// motion is estimated from the views; with rectified they are taken as equally spaced, left to
// right. The views go through the pipeline as run's burst does, depth only and at their full size
// (PipelineConfig::render false, the working size the views' own).
#include <sys/stat.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "algo/pipeline/pipeline.h"
#include "firmware/cli/commands.h"
#include "firmware/cli/options.h"
#include "firmware/codecs/exif.h"
#include "firmware/codecs/image_file.h"
#include "firmware/depth_out/depth_out.h"
#include "firmware/platform/arena_block.h"
#include "firmware/storage/atomic_file.h"
#include "firmware/storage/output_target.h"

namespace lb::cli {
namespace {

const char kUsage[] =
    "usage: refocus depth --views F1 F2 ... --disparity-out D.pfm [options]\n"
    "\n"
    "  --views F1 F2 ...      the views, in the order they were taken (PPM, PGM, PNG or JPEG,\n"
    "                         all the same size)\n"
    "  --geometry G           auto: handheld, the camera motion is estimated from the views\n"
    "                         (default); rectified: equally spaced views, left to right\n"
    "  --focal-35mm F         the lens as a 35 mm equivalent focal length, for auto geometry\n"
    "                         (default: the first file's EXIF, else a ~64 degree field of view)\n"
    "  --ref K                reference view, 0-based (default: the middle one)\n"
    "  --disparity-out D.pfm  disparity of the reference view, px per view step (PFM)\n"
    "  --preview P.png        colour-mapped preview (blue far .. red near)\n"
    "  --labels N             disparity labels, 2..256 (default 64)\n"
    "  --disparity MIN,MAX    label range in px per view step, signed for a converged rig\n"
    "                         (rectified default 0 and (N-1)/4: quarter-pixel labels; auto:\n"
    "                         from the tracked points)\n"
    "  --smoothness W         smoothness weight, for a step of a quarter px of disparity,\n"
    "                         0..%d (default %d)\n"
    "  --cycles N             expansion cycle cap, 0..32 (default %d)\n"
    "  --subpixel             write the sub-label refinement the renderer uses (default: the\n"
    "                         labels' disparities, which score best against whole-pixel truth)\n";

// refocus depth works at the views' full size: views x pixels x (3 bytes of view, about 40 of
// the stage's arena). 2 megapixels keeps 16 views within about 1.5 GB and a typical 5-view
// burst of them within 0.5 GB.
constexpr int64_t kMaxDepthPixels = int64_t{2} << 20;

enum Opt {
  kViews = 256,
  kSubpixel,
  kHelp,
  kDisparityOut,
  kPreview,
  kRef,
  kSmoothness,
  kCycles,
  kDisparity
};

// The largest weight the stage takes at the default truncation.
int32_t MaxSmoothness() { return DepthStage::MaxSmoothWeight(DepthConfig{}.smooth_trunc); }

int Usage(const std::string& problem) { return UsageError("depth", problem); }

int Help() {
  const DepthConfig defaults;
  printf(kUsage, MaxSmoothness(), defaults.smooth_weight, defaults.max_cycles);
  return 0;
}

}  // namespace

int DepthCommand(int argc, char** argv) {
  std::vector<const char*> files;
  const char* pfm = nullptr;
  const char* preview = nullptr;
  int32_t ref = -1;
  JobOptions settings;  // --geometry, --focal-35mm and --labels, as run takes them
  settings.pipeline.geometry = ViewGeometry::kAuto;
  // The depth stage at the views' full size, with its map as the result.
  PipelineConfig& c = settings.pipeline;
  c.subpixel = false;
  c.render = false;
  c.confidence = false;  // the PFM and the preview carry no confidence
  bool range_given = false;
  std::string error;
  std::vector<option> table = WithSettings(
      {
          {"views", no_argument, nullptr, kViews},
          {"subpixel", no_argument, nullptr, kSubpixel},
          {"help", no_argument, nullptr, kHelp},
          {"disparity-out", required_argument, nullptr, kDisparityOut},
          {"preview", required_argument, nullptr, kPreview},
          {"ref", required_argument, nullptr, kRef},
          {"smoothness", required_argument, nullptr, kSmoothness},
          {"cycles", required_argument, nullptr, kCycles},
          {"disparity", required_argument, nullptr, kDisparity},
      },
      {"geometry", "focal-35mm", "labels"});
  // "-": the arguments that are no option come back in place, to be taken as views.
  OptionReader options(argc, argv, std::move(table), "-:h");
  bool in_views = false;  // from --views up to the next option
  auto view = [&](const char* file) {
    if (in_views) {
      files.push_back(file);
    } else {
      error = std::string("unknown option '") + file + "'";
    }
    return in_views;
  };
  for (int o; (o = options.Next(&settings)) != -1;) {
    const char* arg = options.arg();
    bool ok = true;
    if (o != kPositional) in_views = o == kViews;
    switch (o) {
      case 0:
        return Usage(options.error());
      case kPositional:
        ok = view(arg);
        break;
      case kSubpixel:
        c.subpixel = true;
        break;
      case kHelp:
      case 'h':
        return Help();
      case kDisparityOut:
        pfm = arg;
        break;
      case kPreview:
        preview = arg;
        break;
      case kRef:
        ok = ParseWholeNumber(arg, 0, DepthConfig::kMaxViews - 1, &ref, &error);
        break;
      case kSmoothness:
        ok = ParseWholeNumber(arg, 0, MaxSmoothness(), &c.smooth_weight, &error);
        break;
      case kCycles:
        ok = ParseWholeNumber(arg, 0, 32, &c.max_cycles, &error);
        break;
      case kDisparity:
        ok = ParseDisparityRange(arg, &c.disp_min_q8, &c.disp_max_q8, &error);
        range_given = ok;
        break;
    }
    if (!ok) return Usage(error);
  }
  // After "--" every argument is a file, even one that starts with a dash.
  for (int i = options.rest(); i < argc; ++i) {
    if (!view(argv[i])) return Usage(error);
  }
  const ViewGeometry geometry = c.geometry;
  c.plan_range = !range_given;
  if (files.size() < 2) return Usage("--views needs at least two files");
  if (files.size() > static_cast<size_t>(DepthConfig::kMaxViews)) {
    return Usage("--views takes at most 16 files");
  }
  if (!pfm) return Usage("--disparity-out is required");
  c.frames = static_cast<int32_t>(files.size());
  c.reference = ref < 0 ? c.frames / 2 : ref;
  if (c.reference >= c.frames) return Usage("--ref is past the last view");
  if (!range_given) c.disp_max_q8 = (c.labels - 1) * 64;  // quarter-pixel labels from 0

  // Both outputs are checked before any work: devices, links, a missing folder, an input.
  for (const char* target : {pfm, preview}) {
    if (!target) continue;
    const Status check =
        CheckOutputTarget(target, files.data(), static_cast<int32_t>(files.size()));
    if (!check.ok()) return Fail(check.message());
  }
  struct stat a, b;
  if (preview && (!strcmp(preview, pfm) || (stat(pfm, &a) == 0 && stat(preview, &b) == 0 &&
                                            a.st_dev == b.st_dev && a.st_ino == b.st_ino))) {
    return Usage("--preview and --disparity-out name one file");
  }
  // Every header first: sizes are checked before a single pixel buffer exists, so a small
  // file that claims a huge image costs nothing.
  for (size_t v = 0; v < files.size(); ++v) {
    ImageFileInfo info;
    const Status probe = ProbeImageFile(files[v], &info);
    if (!probe.ok()) return Fail(probe.message());
    if (v == 0) {
      c.width = info.width;
      c.height = info.height;
    } else if (info.width != c.width || info.height != c.height) {
      char msg[512];
      snprintf(msg, sizeof(msg), "%s is %dx%d, but %s is %dx%d: the views must match", files[v],
               info.width, info.height, files[0], c.width, c.height);
      return Fail(msg);
    }
  }
  if (int64_t{c.width} * c.height > kMaxDepthPixels) {
    char msg[512];
    snprintf(msg, sizeof(msg),
             "%s: %dx%d views are more than refocus depth works on (%lld pixels, it works at "
             "full size): scale them down, or use refocus run, which works on a smaller copy",
             files[0], c.width, c.height, static_cast<long long>(kMaxDepthPixels));
    return Fail(msg);
  }
  char msg[512];
  if (geometry == ViewGeometry::kAuto &&
      (c.width < MotionConfig::kMinSize || c.height < MotionConfig::kMinSize)) {
    snprintf(msg, sizeof(msg),
             "%s: %dx%d views are too small to follow the camera's motion (at least %dx%d); "
             "--geometry rectified takes aligned views from %dx%d",
             files[0], c.width, c.height, MotionConfig::kMinSize, MotionConfig::kMinSize,
             DepthConfig::kMinSize, DepthConfig::kMinSize);
    return Fail(msg);
  }
  c.max_working_width = c.width;
  c.max_working_height = c.height;
  if (geometry == ViewGeometry::kAuto) {
    c.focal_px = settings.focal_35mm > 0 ? FocalPxFrom35mm(settings.focal_35mm, c.width, c.height)
                                         : ExifFocalPx(files[0], c.width, c.height);
  }
  size_t bytes = 0;
  Status s = Pipeline::RequiredBytes(c, &bytes);
  if (!s.ok()) {
    snprintf(msg, sizeof(msg), "%s: %s", files[0], s.message());
    return Fail(msg);
  }
  ArenaBlock arena;
  Pipeline pipeline;
  s = arena.Reserve(bytes, "for the depth");
  if (s.ok()) s = pipeline.Configure(c, arena.data(), arena.size());
  if (!s.ok()) return Fail(s.message());
  // Each view straight from its file into the pipeline, a strip of rows at a time.
  for (size_t v = 0; v < files.size(); ++v) {
    s = StreamImageFile(files[v], static_cast<int32_t>(v), pipeline);
    if (!s.ok()) return Fail(s.message());
  }
  s = pipeline.ComputeDepth();
  // A burst the motion cannot give depth for is a warning to run (the photo stays sharp), and
  // here the end: there is no map to write.
  if (s.ok()) s = pipeline.depth_warning();
  if (!s.ok()) return Fail(s.message());
  const ConstImageU16 out = pipeline.disparity_q8();
  const DepthConfig& d = pipeline.depth().config();
  // Both outputs are written in full before either is renamed into place: a failed preview
  // leaves no PFM behind.
  const int32_t bias = DepthStage::MapBiasQ8(d);
  AtomicFile pfm_file, preview_file;
  s = pfm_file.Open(pfm);
  if (s.ok()) s = EncodeDisparityPfm(&pfm_file, out, bias);
  if (s.ok() && preview) s = preview_file.Open(preview);
  if (s.ok() && preview) {
    s = EncodeDisparityPreview(&preview_file, out, pipeline.disp_min_q8(), pipeline.disp_max_q8());
  }
  if (s.ok() && preview) s = preview_file.Commit();
  if (s.ok()) s = pfm_file.Commit();
  if (!s.ok()) return Fail(s.message());
  const DepthStats& st = pipeline.depth().stats();
  printf(
      "%s: %dx%d, %d views (reference %d), %d labels %.2f..%.2f px/step, %d cycles, %zu arena "
      "bytes\n",
      pfm, d.width, d.height, d.views, d.reference, d.labels, d.disp_min_q8 / 256.0,
      d.disp_max_q8 / 256.0, st.cycles, st.arena_bytes);
  return 0;
}

}  // namespace lb::cli
