// refocus run: a burst (image files, a folder, or the synthetic scene) -> a refocused JPEG.
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "firmware/app/job.h"
#include "firmware/cli/commands.h"
#include "firmware/cli/options.h"
#include "firmware/codecs/codec_decoder.h"
#include "firmware/storage/output_target.h"
#include "sim/files/file_sensor.h"
#include "sim/synthetic/synthetic_sensor.h"

namespace lb::cli {
namespace {

const char kUsage[] =
    "usage: refocus run [--synthetic | --input DIR | FILE...] --out OUT.jpg [options]\n"
    "\n"
    "Input (default --synthetic):\n"
    "  --synthetic            the built-in synthetic scene (a clone carries no photos)\n"
    "  --input DIR            every .ppm .pgm .png .jpg in DIR, sorted by name, as the burst\n"
    "  FILE...                these files, left to right, as the burst\n"
    "  --seed S               synthetic scene seed (default 1)\n"
    "  --motion M             synthetic camera motion: handheld or rectified (default: handheld\n"
    "                         with --geometry auto, rectified with --geometry rectified)\n"
    "Burst (the synthetic scene's; files bring their own size and count; --size is\n"
    "--resolution's older name):\n";
const char kDepthUsage[] =
    "  --ref K                reference frame, 0-based (default: the middle one)\n"
    "  --disparity MIN,MAX    label range, working px per view step (rectified geometry with\n"
    "                         files; default 0,16; auto geometry finds its own)\n";
const char kOutputUsage[] =
    "Output:\n"
    "  --out OUT.jpg          written atomically: the name holds a whole JPEG or nothing\n"
    "Lens (refocusd.conf takes the same settings, with _ for -):\n";

enum Opt { kSynthetic = 256, kInput, kSeed, kMotion, kRef, kDisparity, kOut, kHelp };

int Help() {
  printf("%s%sDepth:\n%s%s%s%sWork:\n%s", kUsage, SettingsHelp(SettingGroup::kBurst).c_str(),
         SettingsHelp(SettingGroup::kDepth).c_str(), kDepthUsage, kOutputUsage,
         SettingsHelp(SettingGroup::kLens).c_str(), SettingsHelp(SettingGroup::kWork).c_str());
  return 0;
}

int Usage(const std::string& problem) { return UsageError("run", problem); }

}  // namespace

int RunCommand(int argc, char** argv) {
  JobOptions job;
  job.sensor.width = 1280;
  job.sensor.height = 960;
  job.pipeline.reference = -1;  // the middle frame
  std::string input_dir, out_path, error;
  bool synthetic = false, range_given = false;
  const char* synthetic_only = nullptr;  // the last option that only the synthetic scene takes
  const char* synthetic_why = "";
  const char* motion = nullptr;
  job.pipeline.geometry = ViewGeometry::kAuto;
  SceneParams scene;
  int32_t seed = 1;

  std::vector<option> table = WithSettings(
      {
          {"synthetic", no_argument, nullptr, kSynthetic},
          {"input", required_argument, nullptr, kInput},
          {"seed", required_argument, nullptr, kSeed},
          {"motion", required_argument, nullptr, kMotion},
          {"ref", required_argument, nullptr, kRef},
          {"disparity", required_argument, nullptr, kDisparity},
          {"out", required_argument, nullptr, kOut},
          {"help", no_argument, nullptr, kHelp},
      },
      {SettingGroup::kBurst, SettingGroup::kDepth, SettingGroup::kLens, SettingGroup::kWork});
  OptionReader options(argc, argv, std::move(table));
  for (int c; (c = options.Next(&job)) != -1;) {
    const char* arg = options.arg();
    bool ok = true;
    switch (c) {
      case 0:
        return Usage(options.error());
      case kSynthetic:
        synthetic = true;
        break;
      case kInput:
        ok = options.Once(&input_dir, &error);
        break;
      case kSeed:
        ok = ParseWholeNumber(arg, 0, INT32_MAX, &seed, &error);
        synthetic_only = "seed";
        synthetic_why = "files bring their own scene";
        break;
      case kMotion:
        motion = arg;
        synthetic_only = "motion";
        synthetic_why = "files bring their own camera motion";
        ok = !strcmp(arg, "handheld") || !strcmp(arg, "rectified");
        if (!ok) error = std::string("motion '") + arg + "' is neither handheld nor rectified";
        break;
      case kRef:
        ok = ParseWholeNumber(arg, 0, PipelineConfig::kMaxFrames - 1, &job.pipeline.reference,
                              &error);
        break;
      case kDisparity:
        ok = ParseDisparityRange(arg, &job.pipeline.disp_min_q8, &job.pipeline.disp_max_q8, &error);
        range_given = true;
        break;
      case kOut:
        ok = options.Once(&out_path, &error);
        break;
      case kHelp:
        return Help();
      default:  // a setting, already taken into `job`
        if (SettingOfOption(c)->group == SettingGroup::kBurst) {
          synthetic_only = options.name();
          synthetic_why = "files bring their own size and count";
        }
    }
    if (!ok) return Usage(error);
  }
  std::vector<std::string> files(argv + options.rest(), argv + argc);
  if (out_path.empty()) return Usage("--out OUT.jpg is required");
  if (synthetic + !input_dir.empty() + !files.empty() > 1) {
    return Usage("give one input: --synthetic, --input DIR or FILE...");
  }
  if (synthetic_only && (!input_dir.empty() || !files.empty())) {
    return Usage(std::string("--") + synthetic_only +
                 " is for the synthetic scene: " + synthetic_why);
  }

  std::unique_ptr<Sensor> sensor;
  const FileSensor* file_sensor = nullptr;
  if (!input_dir.empty() || !files.empty()) {
    std::unique_ptr<FileSensor> fs;
    const ImageDecoder& codecs = CodecImageDecoder();
    Status s = input_dir.empty() ? FileSensor::FromFiles(files, codecs, &fs)
                                 : FileSensor::FromDirectory(input_dir.c_str(), codecs, &fs);
    if (!s.ok()) return Fail(s.message());
    // Checked once, by the sensor's Configure inside the job's, where the message names a file.
    fs->LimitSize(16, PipelineConfig::kMaxWidth, PipelineConfig::kMaxHeight);
    file_sensor = fs.get();
    sensor = std::move(fs);
    job.sensor.width = job.sensor.height = 0;  // the files decide
    job.model = "Image files";
  } else {
    scene.seed = static_cast<uint64_t>(seed);
    const bool handheld =
        motion ? !strcmp(motion, "handheld") : job.pipeline.geometry == ViewGeometry::kAuto;
    scene.geometry = handheld ? ViewGeometry::kHandheld : ViewGeometry::kRectified;
    if (job.pipeline.reference >= 0) scene.reference = job.pipeline.reference;
    auto synth = std::make_unique<SyntheticSensor>(scene);
    SensorMode mode;
    Status s = synth->Configure(job.sensor, &mode);
    if (!s.ok()) return Fail(s.message());
    const Scene& sc = synth->scene();
    job.pipeline.reference = sc.reference();
    if (!range_given && job.pipeline.geometry == ViewGeometry::kRectified) {
      // The scene knows its depth range: pad it by one label step on each side.
      PipelineConfig probe = job.pipeline;
      probe.width = mode.width;
      probe.height = mode.height;
      const int32_t scale = Pipeline::WorkingScale(probe);
      const int32_t lo = sc.disparity_min_q8(scale), hi = sc.disparity_max_q8(scale);
      const int32_t pad = (hi - lo) / job.pipeline.labels + 1;
      job.pipeline.disp_min_q8 = lo > pad ? lo - pad : 0;
      job.pipeline.disp_max_q8 = hi + pad;
    }
    sensor = std::move(synth);
  }

  Job runner;
  Status s = runner.Configure(sensor.get(), job);
  if (!s.ok()) return Fail(s.message());
  // The inputs are known once the files were probed: the output may be none of them.
  std::vector<const char*> inputs;
  if (file_sensor) {
    for (const std::string& path : file_sensor->paths()) inputs.push_back(path.c_str());
  }
  s = CheckOutputTarget(out_path.c_str(), inputs.data(), static_cast<int32_t>(inputs.size()));
  if (!s.ok()) return Fail(s.message());
  JobReport report;
  TerminalProgress progress(stderr);
  runner.set_progress(&progress);
  s = runner.Run(out_path.c_str(), &report);
  progress.Clear();
  if (!s.ok()) return Fail(s.message());
  if (!report.warning.ok()) {
    fprintf(stderr, "refocus: warning: no depth from this burst, the photo is not blurred: %s\n",
            report.warning.message());
  }
  if (report.hint != nullptr) fprintf(stderr, "refocus: hint: %s\n", report.hint);
  printf(
      "wrote %s: %dx%d, %d frames, focus disparity %.2f px; capture %.2f s, depth %.2f s (motion "
      "%.2f s), render+encode %.2f s, arena %.1f MiB, %d thread%s\n",
      out_path.c_str(), report.width, report.height, runner.mode().frames,
      report.focus_disp_q8 / 256.0, report.capture_s, report.depth_s, report.motion_s,
      report.render_s, static_cast<double>(report.arena_bytes) / (1024.0 * 1024.0),
      runner.pipeline().config().workers, runner.pipeline().config().workers == 1 ? "" : "s");
  const Pipeline& p = runner.pipeline();
  if (job.pipeline.geometry == ViewGeometry::kAuto && report.warning.ok()) {
    printf(
        "motion: %d points followed (reprojection %.2f px)%s, focal length %.0f px%s, depth "
        "labels %.2f..%.2f px per frame\n",
        p.motion().points, p.motion().rms_px,
        p.motion().rail ? ", on a rail (orientation held, lens k1 fitted)" : "",
        p.motion().intrinsics.fx * p.working_scale(),
        job.pipeline.focal_px > 0 || runner.mode().focal_px > 0 ? "" : " (found from the frames)",
        p.depth().config().disp_min_q8 / 256.0, p.depth().config().disp_max_q8 / 256.0);
  }
  return 0;
}

}  // namespace lb::cli
