// refocus rerender: a refocusable JPEG -> the same photo with a new focus or aperture.
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>

#include "firmware/app/rerender.h"
#include "firmware/cli/commands.h"
#include "firmware/cli/options.h"
#include "firmware/storage/output_target.h"

namespace lb::cli {
namespace {

const char kUsage[] =
    "usage: refocus rerender IN.jpg --out OUT.jpg [--focus X,Y[,W,H]] [--f-number N] [options]\n"
    "\n"
    "Renders a new focus from a refocusable JPEG alone (one written by `refocus run`, or a\n"
    "phone's depth photo: any file with a GDepth depth map or Dynamic Depth), no burst needed.\n"
    "Without --focus and --f-number it starts from the file's own focus and blur (GFocus) when\n"
    "it has them. A file without the all-in-focus original (GImage or Dynamic Depth's Original)\n"
    "is refocused from the photo itself, which is already blurred: a warning says so. The new\n"
    "photo carries its depth and original again, as GDepth and as Dynamic Depth.\n"
    "  --out OUT.jpg          written atomically: the name holds a whole JPEG or nothing\n"
    "Lens (refocusd.conf takes the same settings, with _ for -):\n";

enum Opt { kOut = 256, kHelp };

int Usage(const std::string& problem) { return UsageError("rerender", problem); }

}  // namespace

int RerenderCommand(int argc, char** argv) {
  std::vector<option> table = WithSettings(
      {
          {"out", required_argument, nullptr, kOut},
          {"help", no_argument, nullptr, kHelp},
      },
      {SettingGroup::kLens, SettingGroup::kWork});
  OptionReader options(argc, argv, std::move(table));
  JobOptions lens;
  std::string out_path, error;
  bool focus_given = false, f_number_given = false;
  for (int c; (c = options.Next(&lens)) != -1;) {
    if (c == 0) return Usage(options.error());
    if (options.name() != nullptr) {
      focus_given |= strcmp(options.name(), "focus") == 0;
      f_number_given |= strcmp(options.name(), "f-number") == 0;
    }
    if (c == kOut && !options.Once(&out_path, &error)) return Usage(error);
    if (c == kHelp) {
      printf("%s%sWork:\n%s", kUsage, SettingsHelp(SettingGroup::kLens).c_str(),
             SettingsHelp(SettingGroup::kWork).c_str());
      return 0;
    }
  }
  RerenderOptions o;
  o.render = lens.render;
  o.max_blur_radius = lens.pipeline.max_blur_radius;
  o.quality = lens.quality;
  o.threads = lens.threads;
  TerminalProgress progress(stderr);
  o.progress = &progress;
  if (options.rest() != argc - 1) return Usage("give exactly one input file");
  if (out_path.empty()) return Usage("--out OUT.jpg is required");
  const char* input = argv[options.rest()];
  Status s = CheckOutputTarget(out_path.c_str(), &input, 1);
  if (!s.ok()) return Fail(s.message());
  Rerenderer r;
  s = r.Load(input);
  if (s.ok() && r.from_primary()) {
    fprintf(stderr,
            "refocus: warning: %s has no all-in-focus original (GImage): refocusing the photo "
            "itself, already blurred where it was out of focus\n",
            input);
  }
  if (s.ok()) {
    r.StartFromFile(&o.render, focus_given, f_number_given);
    s = r.Render(o, out_path.c_str());
  }
  progress.Clear();
  if (!s.ok()) return Fail(s.message());
  printf("wrote %s: %dx%d re-rendered at f/%.1f\n", out_path.c_str(), r.width(), r.height(),
         static_cast<double>(o.render.f_number));
  return 0;
}

}  // namespace lb::cli
