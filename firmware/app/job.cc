#include "firmware/app/job.h"

#include <cstdio>
#include <ctime>
#include <utility>

#include "algo/motion/camera.h"
#include "firmware/app/focus.h"
#include "firmware/app/refocusable.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/platform/worker_pool.h"
#include "firmware/storage/atomic_file.h"
#include "firmware/storage/output_target.h"

namespace lb {
namespace {

double Now() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

void FormatExifTime(char* out, size_t size) {
  const time_t t = time(nullptr);
  tm local;
  localtime_r(&t, &local);
  strftime(out, size, "%Y:%m:%d %H:%M:%S", &local);
}

Status InsertPending(PendingSegments* pending, JpegWriter* writer) {
  const std::vector<JpegSegment>* segments = nullptr;
  LB_RETURN_IF_ERROR(pending->Take(&segments));
  return writer->InsertSegments(*segments);
}

}  // namespace

Status WriteStrips(RenderStage* render, StripObserver* observer, JpegWriter* writer,
                   Progress* progress, PendingSegments* pending) {
  for (;;) {
    ConstPlanarU8 strip;
    int32_t y0 = 0, rows = 0;
    LB_RETURN_IF_ERROR(render->NextStrip(&strip, &y0, &rows));
    if (rows == 0) break;
    if (observer) observer->OnStrip(strip, y0, rows);
    LB_RETURN_IF_ERROR(writer->WriteStrip(strip, rows));
    // As soon as they are built: the writer holds its output in memory until then.
    if (pending != nullptr && writer->holding() && pending->Ready()) {
      LB_RETURN_IF_ERROR(InsertPending(pending, writer));
    }
    if (progress) {
      const int64_t height = render->config().height;
      progress->Update("render", static_cast<int32_t>(100 * (y0 + rows) / height));
    }
  }
  if (pending != nullptr && writer->holding()) LB_RETURN_IF_ERROR(InsertPending(pending, writer));
  return writer->Finish();
}

namespace {

// Counts the frames a sensor delivers into the pipeline, for the progress line.
class CountingSink final : public FrameSink {
 public:
  CountingSink(FrameSink* next, int32_t frames, Progress* progress)
      : next_(next), frames_(frames), progress_(progress) {}
  Status BeginFrame(const FrameInfo& info) override { return next_->BeginFrame(info); }
  Status Rows(const FrameRows& rows) override { return next_->Rows(rows); }
  Status EndFrame() override {
    LB_RETURN_IF_ERROR(next_->EndFrame());
    ++done_;
    progress_->Update("capture", 100 * done_ / (frames_ > 0 ? frames_ : 1));
    return Status::Ok();
  }

 private:
  FrameSink* next_;
  int32_t frames_, done_ = 0;
  Progress* progress_;
};

// The refocusable XMP of a photo, built on the job's side thread (or inline without one) from
// the reference, the map and its confidence, which the render only reads meanwhile, and the
// Dynamic Depth items it lists, written after the image.
class XmpBuild final : public PendingSegments {
 public:
  XmpBuild(SideTask* side, const Pipeline& p, const FocusUsed& focus, int quality,
           const DdImagingModel& model)
      : side_(side),
        reference_(p.reference()),
        map_(p.map_q8()),
        confidence_(p.map_confidence()),
        range_{p.map_min_q8(), p.map_max_q8()},
        focus_(focus),
        quality_(quality) {
    trailer_.extras.imaging_model = model;
  }
  void Start() { side_->Post(&XmpBuild::Run, this); }
  bool Ready() override { return side_->Done(); }
  Status Take(const std::vector<JpegSegment>** segments) override {
    const double t0 = Now();
    side_->Wait();
    wait_s_ = Now() - t0;
    *segments = &segments_;
    return status_;
  }
  // After the build: its Status, and its segments handed over.
  const Status& status() const { return status_; }
  std::vector<JpegSegment> Release() { return std::move(segments_); }
  const DynamicDepthTrailer& trailer() const { return trailer_; }
  double build_s() const { return build_s_; }
  double wait_s() const { return wait_s_; }

 private:
  static void Run(void* self) { static_cast<XmpBuild*>(self)->Build(); }
  void Build() {
    const double t0 = Now();
    std::vector<uint8_t> original;
    status_ = EncodeYCbCr420(reference_, quality_, &original);
    if (status_.ok()) {
      status_ =
          BuildRefocusableSegments(map_, range_, std::move(original), focus_,
                                   reference_.planes[0].width, &segments_, &trailer_, confidence_);
    }
    build_s_ = Now() - t0;
  }

  SideTask* side_;
  ConstPlanarU8 reference_;
  ConstImageU16 map_;
  ConstImageU8 confidence_;
  DisparityRange range_;
  FocusUsed focus_;
  int quality_;
  Status status_;
  std::vector<JpegSegment> segments_;
  DynamicDepthTrailer trailer_;
  double build_s_ = 0, wait_s_ = 0;
};

// The labeling's moves as the progress line's percentage (when there is a line), and when the
// labeling began: the motion's estimate comes before it.
class DepthProgress final : public ProgressSink {
 public:
  explicit DepthProgress(Progress* progress) : progress_(progress) {}
  void Report(int32_t done, int32_t total) override {
    if (labeling_began_ < 0) labeling_began_ = Now();
    if (progress_ == nullptr) return;
    progress_->Update("depth", static_cast<int32_t>(100 * int64_t{done} / (total > 0 ? total : 1)));
  }
  double labeling_began() const { return labeling_began_; }

 private:
  Progress* progress_;
  double labeling_began_ = -1;
};

}  // namespace

Job::Job() : pipeline_(std::make_unique<Pipeline>()), pool_(std::make_unique<WorkerPool>()) {}
Job::~Job() = default;

Status Job::Configure(Sensor* sensor, const JobOptions& options) {
  sensor_ = sensor;
  options_ = options;
  LB_RETURN_IF_ERROR(sensor_->Configure(options.sensor, &mode_));
  PipelineConfig& pc = options_.pipeline;
  pc.width = mode_.width;
  pc.height = mode_.height;
  pc.frames = mode_.frames;
  if (mode_.focal_px == 0 && options.focal_35mm > 0) {
    mode_.focal_px = FocalPxFrom35mm(options.focal_35mm, mode_.width, mode_.height);
  }
  if (pc.focal_px == 0) pc.focal_px = mode_.focal_px;
  if (pc.reference >= pc.frames) {
    return Status(Code::kInvalidArgument,
                  "reference frame %d is past the burst's %d frames (0..%d)", pc.reference,
                  pc.frames, pc.frames - 1);
  }
  if (pc.reference < 0) pc.reference = pc.frames / 2;
  LB_RETURN_IF_ERROR(CheckFocusRegion(options_.render.focus, mode_.width, mode_.height));
  pc.workers = WorkerPool::CountFor(options.threads);
  size_t bytes = 0;
  LB_RETURN_IF_ERROR(Pipeline::RequiredBytes(pc, &bytes));
  LB_RETURN_IF_ERROR(arena_.Reserve(bytes, "for the pipeline"));
  arena_bytes_ = bytes;
  LB_RETURN_IF_ERROR(pipeline_->Configure(pc, arena_.data(), arena_.size()));
  if (pool_->workers() != pc.workers) LB_RETURN_IF_ERROR(pool_->Start(pc.workers));
  pipeline_->SetRunner(pool_.get());
  // The XMP is built beside the render only when threads were given to the job: one thread
  // means one.
  if (pc.workers > 1 && options_.refocusable) {
    LB_RETURN_IF_ERROR(side_.Start());
  } else {
    side_.Stop();
  }
  return Status::Ok();
}

Status Job::Run(const char* out_path, JobReport* report, StripObserver* observer) {
  if (!sensor_) return Status(Code::kInvalidArgument, "job run before configure");
  JobReport r;
  r.arena_bytes = arena_bytes_;
  r.width = mode_.width;
  r.height = mode_.height;
  Pipeline& p = *pipeline_;
  p.ResetBurst();

  // The destination is checked before the capture, so a device, a link or a missing or
  // read-only folder fails at once; the temporary is created only when the photo is ready to be
  // written, and any later failure removes it, so nothing is left on storage.
  LB_RETURN_IF_ERROR(CheckOutputTarget(out_path, nullptr, 0));
  double t0 = Now();
  if (progress_ != nullptr) {
    progress_->Update("capture", 0);
    CountingSink counting(&p, mode_.frames, progress_);
    LB_RETURN_IF_ERROR(sensor_->CaptureBurst(counting));
  } else {
    LB_RETURN_IF_ERROR(sensor_->CaptureBurst(p));
  }
  double t1 = Now();
  r.capture_s = t1 - t0;
  DepthProgress depth_progress(progress_);
  if (progress_ != nullptr) progress_->Update("depth", 0);
  p.SetProgress(&depth_progress);
  const Status depth = p.ComputeDepth();
  p.SetProgress(nullptr);
  LB_RETURN_IF_ERROR(depth);
  // A burst without depth skips the labeling: its stage is over all the same.
  if (progress_ != nullptr) progress_->Update("depth", 100);
  double t2 = Now();
  r.depth_s = t2 - t1;
  r.motion_s =
      depth_progress.labeling_began() >= 0 ? depth_progress.labeling_began() - t1 : r.depth_s;
  r.warning = p.depth_warning();
  r.low_confidence_permille = p.low_confidence_permille();
  // A burst without depth has its own warning, which says what to do.
  if (r.warning.ok() && Pipeline::MostlyGuess(r.low_confidence_permille)) r.hint = kRetakeHint;

  LB_RETURN_IF_ERROR(p.BeginRender(options_.render));
  r.focus_disp_q8 = p.render().focus_disp_q8();

  JpegMetadata meta;
  meta.make = options_.make;
  meta.model = options_.model;
  meta.software = options_.software;
  char when[32];
  FormatExifTime(when, sizeof(when));
  meta.datetime_original = when;
  meta.f_number = options_.render.f_number;
  // The frames' orientation goes with the pixels (and the depth map, stored the same way).
  meta.orientation = mode_.orientation;
  if (mode_.focal_px > 0) {
    meta.focal_35mm =
        static_cast<int32_t>(Focal35mmFromPx(mode_.focal_px, mode_.width, mode_.height) + 0.5);
  }
  // The XMP precedes the image data. With a side thread it is built there while the first
  // strips render and encode, and the writer holds their bytes until it comes (the file's bytes
  // are the same); otherwise it is built here first.
  XmpBuild xmp(&side_, p, FocusOf(p.render(), options_.render, mode_.width, mode_.height),
               options_.quality, ImagingModelOf(mode_.focal_px, mode_.width, mode_.height));
  SideTaskGuard joined(&side_);  // declared after `xmp`: its build never outlives it
  PendingSegments* pending = nullptr;
  if (options_.refocusable) {
    if (side_.started()) {
      xmp.Start();
      meta.segments_later = true;
      pending = &xmp;
    } else {
      xmp.Start();  // runs here
      LB_RETURN_IF_ERROR(xmp.status());
      meta.extra_segments = xmp.Release();
    }
  }
  AtomicFile file;
  LB_RETURN_IF_ERROR(file.Open(out_path));
  JpegWriter writer;
  LB_RETURN_IF_ERROR(writer.Begin(&file, mode_.width, mode_.height, options_.quality, meta));
  LB_RETURN_IF_ERROR(WriteStrips(&p.render(), observer, &writer, progress_, pending));
  if (options_.refocusable) LB_RETURN_IF_ERROR(WriteDynamicDepthTrailer(xmp.trailer(), &file));
  r.metadata_s = xmp.build_s();
  r.metadata_wait_s = pending != nullptr ? xmp.wait_s() : 0;
  if (progress_ != nullptr) progress_->Update("write", 100);
  LB_RETURN_IF_ERROR(file.Commit(options_.replace));
  r.render_s = Now() - t2;
  if (report) *report = r;
  return Status::Ok();
}

}  // namespace lb
