// refocus run: a burst (image files, a folder, or the synthetic scene) -> a refocused JPEG.
#include <getopt.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "firmware/app/job.h"
#include "firmware/cli/commands.h"
#include "firmware/cli/options.h"
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
    "  --size WxH             synthetic frame size (default 1280x960, 16x16 .. 8192x8192)\n"
    "  --frames N             synthetic burst length (default 5)\n"
    "  --seed S               synthetic scene seed (default 1)\n"
    "  --motion M             synthetic camera motion: handheld or rectified (default: handheld\n"
    "                         with --geometry auto, rectified with --geometry rectified)\n"
    "Depth:\n"
    "  --geometry G           auto: a handheld burst, the camera motion is estimated from the\n"
    "                         frames (default); rectified: equally spaced views, left to right\n"
    "  --focal-35mm F         the lens as a 35 mm equivalent focal length (auto geometry; "
    "default:\n"
    "                         the sensor's or the files' EXIF, else a ~64 degree field of view)\n"
    "  --ref K                reference frame, 0-based (default: the middle one)\n"
    "  --labels N             depth labels (default 64)\n"
    "  --disparity MIN,MAX    label range, working px per view step (rectified geometry with\n"
    "                         files; default 0,16; auto geometry finds its own)\n"
    "  --working-size WxH     largest working resolution for depth (default 640x480)\n"
    "Output:\n"
    "  --out OUT.jpg          written atomically: the name holds a whole JPEG or nothing\n";

enum Opt {
  kSynthetic = 256,
  kInput,
  kSize,
  kFrames,
  kSeed,
  kMotion,
  kGeometry,
  kFocal,
  kRef,
  kLabels,
  kDisparity,
  kWorking,
  kOut,
  kHelp
};

int Usage(const std::string& error) {
  fprintf(stderr, "refocus run: %s ('refocus run --help' lists the options)\n", error.c_str());
  return 2;
}

}  // namespace

int RunCommand(int argc, char** argv) {
  JobOptions job;
  job.sensor.width = 1280;
  job.sensor.height = 960;
  job.pipeline.reference = -1;  // the middle frame
  std::string input_dir, out_path, error;
  bool synthetic = false, range_given = false;
  const char* synthetic_only = nullptr;  // the last option that only the synthetic scene takes
  const char* motion = nullptr;
  job.pipeline.geometry = Geometry::kAuto;
  SceneParams scene;
  int32_t seed = 1;

  const std::vector<option> options = WithLensOptions({
      {"synthetic", no_argument, nullptr, kSynthetic},
      {"input", required_argument, nullptr, kInput},
      {"size", required_argument, nullptr, kSize},
      {"frames", required_argument, nullptr, kFrames},
      {"seed", required_argument, nullptr, kSeed},
      {"motion", required_argument, nullptr, kMotion},
      {"geometry", required_argument, nullptr, kGeometry},
      {"focal-35mm", required_argument, nullptr, kFocal},
      {"ref", required_argument, nullptr, kRef},
      {"labels", required_argument, nullptr, kLabels},
      {"disparity", required_argument, nullptr, kDisparity},
      {"working-size", required_argument, nullptr, kWorking},
      {"out", required_argument, nullptr, kOut},
      {"help", no_argument, nullptr, kHelp},
  });
  LensOptions lens;
  optind = 1;
  opterr = 0;  // the messages below say it in one line
  for (int c; (c = getopt_long(argc, argv, ":", options.data(), nullptr)) != -1;) {
    bool ok = true;
    switch (c) {
      case kSynthetic:
        synthetic = true;
        break;
      case kInput:
        ok = input_dir.empty();
        if (!ok) error = "--input given twice";
        input_dir = optarg;
        break;
      case kSize:
        ok = ParseSize(optarg, &job.sensor.width, &job.sensor.height, &error);
        synthetic_only = "--size";
        break;
      case kFrames:
        ok = ParseInt(optarg, 1, 16, &job.sensor.frames, &error);
        synthetic_only = "--frames";
        break;
      case kSeed:
        ok = ParseInt(optarg, 0, INT32_MAX, &seed, &error);
        break;
      case kMotion:
        motion = optarg;
        ok = !strcmp(optarg, "handheld") || !strcmp(optarg, "rectified");
        if (!ok) error = std::string("motion '") + optarg + "' is neither handheld nor rectified";
        break;
      case kGeometry:
        ok = ParseGeometry(optarg, &job.pipeline.geometry, &error);
        break;
      case kFocal:
        ok = ParseInt(optarg, 8, 2000, &job.focal_35mm, &error);
        break;
      case kRef:
        ok = ParseInt(optarg, 0, 15, &job.pipeline.reference, &error);
        break;
      case kLabels:
        ok = ParseInt(optarg, 2, 256, &job.pipeline.labels, &error);
        break;
      case kDisparity:
        ok = ParseDisparityRange(optarg, &job.pipeline.disp_min_q8, &job.pipeline.disp_max_q8,
                                 &error);
        range_given = true;
        break;
      case kWorking:
        ok = ParseSize(optarg, &job.pipeline.max_working_width, &job.pipeline.max_working_height,
                       &error);
        break;
      case kOut:
        ok = out_path.empty();
        if (!ok) error = "--out given twice";
        out_path = optarg;
        break;
      case kHelp:
        printf("%s%s", kUsage, kLensUsage);
        return 0;
      case ':':
        return Usage(std::string(argv[optind - 1]) + " needs a value");
      case '?':
        return Usage(std::string("unknown option '") + argv[optind - 1] + "'");
      default:
        ok = ParseLensOption(c, optarg, &lens, &error);
    }
    if (!ok) return Usage(error);
  }
  job.render = lens.render;
  job.pipeline.max_blur_radius = lens.max_radius;
  job.quality = lens.quality;
  std::vector<std::string> files(argv + optind, argv + argc);
  if (out_path.empty()) return Usage("--out OUT.jpg is required");
  if (synthetic + !input_dir.empty() + !files.empty() > 1) {
    return Usage("give one input: --synthetic, --input DIR or FILE...");
  }
  if (synthetic_only && (!input_dir.empty() || !files.empty())) {
    return Usage(std::string(synthetic_only) +
                 " is for the synthetic scene: files bring their own size and count");
  }

  std::unique_ptr<Sensor> sensor;
  const FileSensor* file_sensor = nullptr;
  if (!input_dir.empty() || !files.empty()) {
    std::unique_ptr<FileSensor> fs;
    Status s = input_dir.empty() ? FileSensor::FromFiles(files, &fs)
                                 : FileSensor::FromDirectory(input_dir.c_str(), &fs);
    if (!s.ok()) return Fail(s.message());
    file_sensor = fs.get();
    sensor = std::move(fs);
    job.sensor.width = job.sensor.height = 0;  // the files decide
    job.model = "Image files";
  } else {
    scene.seed = static_cast<uint64_t>(seed);
    const bool handheld =
        motion ? !strcmp(motion, "handheld") : job.pipeline.geometry == Geometry::kAuto;
    scene.motion = handheld ? CameraMotion::kHandheld : CameraMotion::kRectified;
    if (job.pipeline.reference >= 0) scene.reference = job.pipeline.reference;
    auto synth = std::make_unique<SyntheticSensor>(scene);
    SensorMode mode;
    Status s = synth->Configure(job.sensor, &mode);
    if (!s.ok()) return Fail(s.message());
    const Scene& sc = synth->scene();
    job.pipeline.reference = sc.reference();
    if (!range_given && job.pipeline.geometry == Geometry::kRectified) {
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
  s = runner.Run(out_path.c_str(), &report);
  if (!s.ok()) return Fail(s.message());
  if (!report.warning.ok()) {
    fprintf(stderr, "refocus: warning: no depth from this burst, the photo is not blurred: %s\n",
            report.warning.message());
  }
  printf(
      "wrote %s: %dx%d, %d frames, focus disparity %.2f px; capture %.2f s, depth %.2f s, "
      "render+encode %.2f s, arena %.1f MiB\n",
      out_path.c_str(), report.width, report.height, runner.mode().frames,
      report.focus_disp_q8 / 256.0, report.capture_s, report.depth_s, report.render_s,
      static_cast<double>(report.arena_bytes) / (1024.0 * 1024.0));
  const Pipeline& p = runner.pipeline();
  if (job.pipeline.geometry == Geometry::kAuto && report.warning.ok()) {
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
