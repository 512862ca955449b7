// The lens-blur pipeline: configure once, ingest a burst frame by frame, compute depth, render
// strip by strip. All memory is one arena sized by RequiredBytes() from the configuration; after
// Configure nothing is allocated. The motion and depth stages and the render take turns in one
// region of it.
//
//   size_t bytes = 0;
//   Status s = Pipeline::RequiredBytes(config, &bytes);   // validates too
//   Pipeline p;  s = p.Configure(config, block, bytes);  // block: 64-byte aligned
//   sensor.CaptureBurst(p)  // p is a FrameSink: BeginFrame / Rows... / EndFrame per frame
//   s = p.ComputeDepth();   // Ok with p.depth_warning() set when the burst gave no depth
//   (config.render false: a depth-only run ends here, the map in p.disparity_q8())

//   s = p.BeginRender(params);  while (p.NextStrip(&strip, &y0, &rows), rows > 0) encode(strip);
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/frame.h"
#include "algo/core/image.h"
#include "algo/core/status.h"
#include "algo/core/task_runner.h"
#include "algo/depth/depth_stage.h"
#include "algo/depth/fattening_trim.h"
#include "algo/motion/camera.h"
#include "algo/motion/motion_stage.h"
#include "algo/render/depth_refine.h"
#include "algo/render/render_stage.h"

namespace lb {

struct PipelineConfig {
  static constexpr int32_t kMaxFrames = DepthConfig::kMaxViews;
  static constexpr int32_t kMaxWidth = kMaxFrameSide;
  static constexpr int32_t kMaxHeight = kMaxFrameSide;

  int32_t width = 0;  // sensor frames, full resolution
  int32_t height = 0;
  int32_t frames = 5;     // burst length
  int32_t reference = 2;  // the view the output is rendered from
  // The depth stage runs at the full resolution divided by the smallest integer factor that
  // brings it within this many pixels (width x height), neither side longer than the longer of
  // the two: a 4:3 frame fits the box either way round, a square one keeps its pixel budget.
  int32_t max_working_width = 680;
  int32_t max_working_height = 510;
  int32_t labels = 64;
  // kRectified (laboratory data) or kAuto (a handheld burst, or any whose poses are unknown).
  ViewGeometry geometry = ViewGeometry::kRectified;
  // Disparity range of the labels, in working-resolution px per view step, Q8.8 (kRectified;
  // kAuto sets it from the tracked points, see auto_geometry.h).
  int32_t disp_min_q8 = 0;
  int32_t disp_max_q8 = 16 << 8;
  // Focal length in full-resolution px (kAuto); 0 assumes DefaultIntrinsics' field of view.
  double focal_px = 0;
  int32_t max_blur_radius = 32;  // full-resolution px
  // Workers the stages carve scratch for (task_runner.h): the most SetRunner may hand in.
  int32_t workers = 1;
  // The depth stage's tuning (depth_stage.h): its own defaults unless a caller chooses.
  int32_t smooth_weight = DepthConfig{}.smooth_weight;
  int32_t max_cycles = DepthConfig{}.max_cycles;
  bool subpixel = DepthConfig{}.subpixel;
  // The depth map's confidence (confidence() below; DepthConfig::confidence).
  bool confidence = DepthConfig{}.confidence;
  // kAuto: the label range planned from the tracked points; false: disp_min_q8..disp_max_q8
  // as given, only the planes follow the motion.
  bool plan_range = true;
  // false: a depth-only run (`refocus depth`): nothing is carved for the render, ComputeDepth
  // is the last step and disparity_q8() its result, and frames may be as small as the depth
  // stage takes (DepthConfig::kMinSize a side).
  bool render = true;
};

class Pipeline : public FrameSink {
 public:
  // Validates `config` and reports the arena bytes it needs.
  static Status RequiredBytes(const PipelineConfig& config, size_t* bytes);

  // The integer factor between the full and the working resolution for this configuration.
  static int32_t WorkingScale(const PipelineConfig& config) { return Plan(config).scale; }
  // The same for the map a photo carries (map_scale()).
  static int32_t MapScale(const PipelineConfig& config) { return Plan(config).map_scale; }

  // Carves `arena` (at least RequiredBytes, 64-byte aligned). Resets any previous burst.
  Status Configure(const PipelineConfig& config, void* arena, size_t bytes);

  // Where the stages run their tasks (borrowed; nullptr: on the caller), with at most
  // config.workers workers. The output bits do not depend on it.
  void SetRunner(TaskRunner* runner);
  // Told how far ComputeDepth's labeling is (borrowed; nullptr: nobody).
  void SetProgress(ProgressSink* progress) { depth_.SetProgress(progress); }

  // FrameSink: frames 0..frames-1 in any order, each exactly once, each covering every row.
  Status BeginFrame(const FrameInfo& info) override;
  Status Rows(const FrameRows& rows) override;
  Status EndFrame() override;

  // Forgets the frames ingested so far; the configuration stays.
  void ResetBurst();

  // Depth for the burst. With kAuto, a burst that cannot give depth (the camera did not move,
  // only turned, or a frame is blurred: see MotionDiagnosis) is not an error: the disparity is
  // flat, so the render keeps everything sharp, and depth_warning() says what to do.
  Status ComputeDepth();
  const Status& depth_warning() const { return depth_warning_; }
  // The disparity map's range of the last ComputeDepth (the labels', configured for
  // kRectified), in the map's units: a signed range is lifted to start at 0 (depth_stage.h).
  int32_t disp_min_q8() const { return disp_min_q8_; }
  int32_t disp_max_q8() const { return disp_max_q8_; }
  // The motion stage's result; its point arrays (point_xy, inv_depth) live in memory the render
  // reuses: valid until BeginRender. The depth stage's labels() and confidence() are taken over
  // by the map before ComputeDepth returns.
  const MotionResult& motion() const { return motion_result_; }
  Status BeginRender(const RenderParams& params);
  Status NextStrip(ConstPlanarU8* strip, int32_t* y0, int32_t* rows);

  const PipelineConfig& config() const { return config_; }
  int32_t working_scale() const { return scale_; }
  int32_t working_width() const { return work_w_; }
  int32_t working_height() const { return work_h_; }
  ConstPlanarU8 reference() const { return ref_.AsConst(); }
  ConstImageU8 working_view(int32_t i) const { return working_[i].AsConst(); }
  ConstImageU16 disparity_q8() const { return disp_q8_.AsConst(); }
  // After ComputeDepth, with config().confidence: how sure each pixel of disparity_q8() is,
  // 0..255 (255: sure; algo/depth/confidence.h), all 0 when the burst gave no depth; an empty
  // image without it. Kept until the next burst's ComputeDepth, the render does not touch it.
  ConstImageU8 confidence() const { return confidence_.AsConst(); }
  // The whole burst's: the share of its pixels whose depth is a guess (confidence below
  // kGuessConfidence), per mille (1000 when it gave no depth, 0 without the map). Above
  // kRetakePermille most of the picture's depth is a guess (a white wall, the sky, a burst
  // without texture): worth a retake hint. A guess is far below DepthStage::kLowConfidence: a
  // fully textured scene has a quarter or so of its pixels under kGuessConfidence (where
  // the smoothness chose a label the data did not: docs/accuracy.md) and about half under
  // kLowConfidence, a flat patch all of them.
  int32_t low_confidence_permille() const { return low_confidence_permille_; }
  static constexpr int32_t kRetakePermille = 500;
  // The one rule the camera's hint and its page both apply to such a share.
  static bool MostlyGuess(int32_t permille) { return permille > kRetakePermille; }
  static constexpr uint8_t kGuessConfidence = 8;
  // The same share for any confidence map (a photo's, read back from its file): per mille of
  // its pixels under kGuessConfidence, 0 for an empty map.
  static int32_t GuessPermille(ConstImageU8 confidence);
  // The depth map a photo carries and the render uses (the file's GDepth and Dynamic Depth),
  // after ComputeDepth: the depth stage's disparity refined on a grid of map_scale()
  // full-resolution px a map px (depth_refine.h), in map px per view step (Q8.8) within
  // map_min_q8()..map_max_q8(), and its confidence (0..255, empty without config().confidence),
  // the same size as the map.
  int32_t map_scale() const { return map_scale_; }
  ConstImageU16 map_q8() const { return map_q8_.AsConst(); }
  ConstImageU8 map_confidence() const { return map_confidence_.AsConst(); }
  int32_t map_min_q8() const { return ToMapQ8(disp_min_q8_); }
  int32_t map_max_q8() const { return ToMapQ8(disp_max_q8_); }
  const DepthStage& depth() const { return depth_; }
  RenderStage& render() { return render_; }

 private:
  struct Layout {
    int32_t scale, work_w, work_h, map_scale;
  };
  static Layout Plan(const PipelineConfig& config);
  Status Carve(Arena& arena);
  void CarveMap(const RefineConfig& fc, Arena& arena);
  Status EstimateGeometry(const ConstImageU8* views);
  void MakeMap(bool flat);
  RefineConfig MakeRefineConfig() const;
  int32_t ToMapQ8(int32_t working_q8) const {
    return (working_q8 * scale_ + map_scale_ / 2) / map_scale_;
  }
  // A band of columns of the ingest: full resolution [x0, x1), working [wx0, wx1).
  struct Columns {
    int32_t x0, x1, wx0, wx1;
  };
  void IngestRow(const uint8_t* src, const uint8_t* u, const uint8_t* v, int32_t y,
                 const Columns& columns);
  void FlushChroma(int32_t y, const Columns& columns);

  PipelineConfig config_;
  int32_t scale_ = 1, work_w_ = 0, work_h_ = 0, map_scale_ = 1;

  PlanarU8 ref_;                                 // full-resolution reference, YCbCr 4:2:0
  ImageU8 working_[PipelineConfig::kMaxFrames];  // working-resolution views, RGB8
  ImageU16 disp_q8_;                             // working-resolution disparity, Q8.8
  ImageU8 confidence_;                           // its confidence (config_.confidence)
  ImageU16 map_q8_;                              // the refined map, Q8.8 map px
  ImageU8 map_confidence_;
  int32_t low_confidence_permille_ = 0;
  uint8_t* rgb_rows_[2] = {nullptr, nullptr};  // full-width RGB8 rows (even, odd)
  uint32_t* cols_ = nullptr;  // box downscale: column sums, working row x scale x 3 (ingest.h)
  DepthStage depth_;
  RenderStage render_;
  FatteningTrim trim_;
  DepthRefiner refine_;
  uint8_t* region_ = nullptr;  // the stages' shared region
  size_t region_bytes_ = 0, analysis_bytes_ = 0;
  MotionStage motion_;  // kAuto only
  InlineRunner inline_;
  TaskRunner* runner_ = &inline_;
  MotionResult motion_result_;
  PlaneHomography* planes_ = nullptr;  // kAuto: frames x labels, view-major
  uint8_t* order_scratch_ = nullptr;   // kAuto: DepthOrderScratchBytes, in depth_.spare()
  int32_t disp_min_q8_ = 0, disp_max_q8_ = 0;
  Status depth_warning_;

  // Burst state.
  uint32_t received_mask_ = 0;
  bool in_frame_ = false;
  FrameInfo frame_;
  int32_t next_row_ = 0;
  bool depth_ready_ = false;
  bool render_started_ = false;
};

}  // namespace lb
