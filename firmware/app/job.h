// A refocus job: one burst from a sensor through the pipeline into a refocused JPEG on storage.
// Configure sizes everything once (the arena is allocated there and reused for every burst);
// Run captures, computes depth, renders strip by strip into the encoder and commits the file
// atomically. The host command line and the device daemon are thin wrappers around it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "algo/pipeline/pipeline.h"
#include "firmware/app/progress.h"
#include "firmware/app/side_task.h"
#include "firmware/platform/arena_block.h"
#include "firmware/storage/atomic_file.h"
#include "hal/sensor.h"

namespace lb {

class WorkerPool;

struct JobOptions {
  SensorConfig sensor;      // requested size and burst length
  PipelineConfig pipeline;  // width/height/frames are taken from the sensor's mode
  RenderParams render;
  int quality = 92;
  // Worker threads for the pipeline, 1..kMaxWorkers; 0: one per core this process may use.
  int32_t threads = 0;
  // The lens as a 35 mm equivalent focal length, mm, when the sensor does not report one
  // (0 = unknown: the pipeline assumes a typical field of view).
  int32_t focal_35mm = 0;
  // Embed the depth map, the all-in-focus original and the focus (GDepth/GImage/GFocus XMP) so
  // the photo can be refocused later (`refocus rerender`, Google Photos and other viewers).
  bool refocusable = true;
  // Whether the photo may go over a regular file of its name (`refocus run --out`, a re-run) or
  // never (the camera's numbered photos: a taken name fails the photo rather than lose another).
  AtomicFile::Replace replace = AtomicFile::Replace::kRegularFile;
  const char* make = "LensBlur";
  const char* model = "Simulated camera";
  const char* software = "refocus";
};

struct JobReport {
  double capture_s = 0, depth_s = 0, render_s = 0;  // wall time of each stage
  // Within depth_s: the camera motion's estimate (auto geometry) before the labeling began; all
  // of depth_s when a burst gave no depth.
  double motion_s = 0;
  // Within render_s: building the refocusable XMP (the original's JPEG, the depth PNG, base64,
  // MD5), beside the render when there are workers to spare, and how long the writer then waited
  // for it after the last strip.
  double metadata_s = 0, metadata_wait_s = 0;
  size_t arena_bytes = 0;
  int32_t focus_disp_q8 = 0;
  int32_t width = 0, height = 0;
  // Not ok when the burst gave no depth (kDegenerate, with what to do): the photo was saved
  // unblurred.
  Status warning;
  // The share of the picture whose depth is a guess (Pipeline::low_confidence_permille), and
  // kRetakeHint when that is most of it and the burst gave depth all the same (nullptr
  // otherwise): what the user is told, one line.
  int32_t low_confidence_permille = 0;
  const char* hint = nullptr;
};

inline constexpr char kRetakeHint[] =
    "most of this photo's depth is a guess (a flat or textureless scene): retake with more "
    "texture in view, or move the camera more between frames";

// Receives each rendered strip as the encoder does (tests use it to checksum the output).
class StripObserver {
 public:
  virtual ~StripObserver() = default;
  virtual void OnStrip(const ConstPlanarU8& strip, int32_t y0, int32_t rows) = 0;
};

class JpegWriter;
struct JpegSegment;

// Segments still being built (on a SideTask) for a writer begun with
// JpegMetadata::segments_later.
class PendingSegments {
 public:
  virtual ~PendingSegments() = default;
  // Whether they are built (never blocks).
  virtual bool Ready() = 0;
  // Waits until they are built; the build's Status, and on success the segments.
  virtual Status Take(const std::vector<JpegSegment>** segments) = 0;
};

// Encodes every strip `render` gives, showing each to `observer` (may be nullptr) first and
// telling `progress` (may be nullptr) the rows done, then finishes the image: a burst's photo and
// a re-render are written the same way. With `pending`, its segments are inserted after the
// first strip that finds them built (at the latest before the image is finished).
Status WriteStrips(RenderStage* render, StripObserver* observer, JpegWriter* writer,
                   Progress* progress = nullptr, PendingSegments* pending = nullptr);

class Job {
 public:
  Job();
  ~Job();
  Job(const Job&) = delete;
  Job& operator=(const Job&) = delete;

  // Configures `sensor` (borrowed for the Job's lifetime) and allocates the pipeline arena.
  Status Configure(Sensor* sensor, const JobOptions& options);
  // One burst -> `out_path`. On failure nothing is left under `out_path`.
  Status Run(const char* out_path, JobReport* report, StripObserver* observer = nullptr);

  // Told each stage's progress during Run (borrowed; nullptr: nobody).
  void set_progress(Progress* progress) { progress_ = progress; }

  Pipeline& pipeline() { return *pipeline_; }
  const SensorMode& mode() const { return mode_; }

 private:
  Sensor* sensor_ = nullptr;
  JobOptions options_;
  SensorMode mode_;
  std::unique_ptr<Pipeline> pipeline_;
  std::unique_ptr<WorkerPool> pool_;
  // With more than one worker: where the refocusable XMP is built while the render runs.
  SideTask side_;
  Progress* progress_ = nullptr;
  ArenaBlock arena_;
  size_t arena_bytes_ = 0;  // what the pipeline asked for
};

}  // namespace lb
