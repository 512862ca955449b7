// refocus rerender: a refocusable JPEG -> the same photo with a new focus or aperture.
#include <getopt.h>

#include <cstdio>
#include <string>

#include "firmware/app/rerender.h"
#include "firmware/cli/commands.h"
#include "firmware/cli/options.h"

namespace lb::cli {
namespace {

const char kUsage[] =
    "usage: refocus rerender IN.jpg --out OUT.jpg [--focus X,Y[,W,H]] [--f-number N] [options]\n"
    "\n"
    "Renders a new focus from a refocusable JPEG alone (one written by `refocus run`, or any file\n"
    "with a RangeInverse GDepth depth map and a GImage original), no burst needed.\n"
    "  --focus X,Y[,W,H]      point or rectangle to keep sharp (default: the centre)\n"
    "  --f-number N           aperture as on a lens, 1.4 .. 16 (default 2.8)\n"
    "  --aperture SHAPE       disc (default), or N-blade (3..12)\n"
    "  --rotation DEG, --curvature C, --highlight-threshold T, --highlight-gain G\n"
    "  --max-radius R         largest blur radius in px (default 32)\n"
    "  --quality Q            JPEG quality 1..100 (default 92)\n";

enum Opt {
  kFocus = 256,
  kFNumber,
  kAperture,
  kRotation,
  kCurvature,
  kHiT,
  kHiG,
  kMaxR,
  kOut,
  kQ,
  kHelp
};

const option kOptions[] = {
    {"focus", required_argument, nullptr, kFocus},
    {"f-number", required_argument, nullptr, kFNumber},
    {"aperture", required_argument, nullptr, kAperture},
    {"rotation", required_argument, nullptr, kRotation},
    {"curvature", required_argument, nullptr, kCurvature},
    {"highlight-threshold", required_argument, nullptr, kHiT},
    {"highlight-gain", required_argument, nullptr, kHiG},
    {"max-radius", required_argument, nullptr, kMaxR},
    {"out", required_argument, nullptr, kOut},
    {"quality", required_argument, nullptr, kQ},
    {"help", no_argument, nullptr, kHelp},
    {nullptr, 0, nullptr, 0},
};

int Usage(const std::string& error) {
  fprintf(stderr, "refocus rerender: %s\n\n%s", error.c_str(), kUsage);
  return 2;
}

}  // namespace

int RerenderCommand(int argc, char** argv) {
  RerenderOptions o;
  std::string out_path, error;
  optind = 1;
  for (int c; (c = getopt_long(argc, argv, "", kOptions, nullptr)) != -1;) {
    bool ok = true;
    switch (c) {
      case kFocus:
        ok = ParseFocus(optarg, &o.render.focus, &error);
        break;
      case kFNumber:
        ok = ParseFloat(optarg, 1.0f, 22.0f, &o.render.f_number, &error);
        break;
      case kAperture:
        ok = ParseAperture(optarg, &o.render.aperture, &error);
        break;
      case kRotation:
        ok = ParseFloat(optarg, -360.0f, 360.0f, &o.render.aperture.rotation_deg, &error);
        break;
      case kCurvature:
        ok = ParseFloat(optarg, 0.0f, 1.0f, &o.render.aperture.curvature, &error);
        break;
      case kHiT: {
        int32_t t = 255;
        ok = ParseInt(optarg, 0, 255, &t, &error);
        o.render.highlight_threshold = static_cast<uint8_t>(t);
        break;
      }
      case kHiG:
        ok = ParseFloat(optarg, 1.0f, 8.0f, &o.render.highlight_gain, &error);
        break;
      case kMaxR:
        ok = ParseInt(optarg, 0, 128, &o.max_blur_radius, &error);
        break;
      case kOut:
        out_path = optarg;
        break;
      case kQ:
        ok = ParseInt(optarg, 1, 100, &o.quality, &error);
        break;
      case kHelp:
        fputs(kUsage, stdout);
        return 0;
      default:
        return Usage("unknown option");
    }
    if (!ok) return Usage(error);
  }
  if (optind != argc - 1) return Usage("give exactly one input file");
  if (out_path.empty()) return Usage("--out OUT.jpg is required");
  Rerenderer r;
  Status s = r.Load(argv[optind]);
  if (s.ok()) s = r.Render(o, out_path.c_str());
  if (!s.ok()) return Fail(s.message());
  printf("wrote %s: %dx%d re-rendered at f/%.1f\n", out_path.c_str(), r.width(), r.height(),
         static_cast<double>(o.render.f_number));
  return 0;
}

}  // namespace lb::cli
