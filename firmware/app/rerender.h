// Re-renders a refocusable JPEG with a new focus or aperture, from the file alone: the stored
// depth map (GDepth) and the all-in-focus original (GImage) go through the same render stage as
// a fresh burst, and the result is written refocusable again. Host-side tool: allocates.
#pragma once

#include <cstdint>
#include <vector>

#include "algo/core/frame.h"
#include "algo/core/image.h"
#include "algo/render/render_stage.h"
#include "firmware/app/job.h"
#include "firmware/app/progress.h"
#include "firmware/refocusable/depth_encoding.h"
#include "firmware/refocusable/xmp_writer.h"

namespace lb {

struct RerenderOptions {
  RenderParams render;
  int32_t max_blur_radius = 32;
  int quality = 92;
  int32_t threads = 0;           // as JobOptions::threads
  Progress* progress = nullptr;  // told how far the render is (borrowed)
};

// What a re-render writes besides the pixels: the depth the file carried, its all-in-focus
// original and its orientation, so the new photo is refocusable again.
struct RerenderSource {
  ConstImageU16 disp_q8;
  DisparityRange range;
  const std::vector<uint8_t>* original_jpeg = nullptr;
  int32_t orientation = 0;
  int32_t width = 0, height = 0;
};

// The writing half of every re-render (`refocus rerender` and the web page's engine): `render`
// has begun with `params`; its strips go through `observer` (may be nullptr) into a refocusable
// JPEG written atomically at `out_path`. Allocates the metadata (XMP, EXIF) while it writes.
// `replace`: whether out_path may be a regular file already (AtomicFile::Commit).
Status WriteRerendered(RenderStage* render, const RenderParams& params,
                       const RerenderSource& source, int quality, const char* software,
                       StripObserver* observer, Progress* progress, const char* out_path,
                       AtomicFile::Replace replace = AtomicFile::Replace::kRegularFile);

// The all-in-focus original's rows, as an image reader streams them, into YCbCr 4:2:0 planes
// (the conversion the pipeline applies to a sensor's reference frame): `y` holds width x height
// bytes, `cb` and `cr` a quarter each (rounded up), `rgb` two rows of RGB8. Nothing allocated.
class Ycc420Sink final : public FrameSink {
 public:
  Ycc420Sink(uint8_t* y, uint8_t* cb, uint8_t* cr, uint8_t* rgb)
      : y_(y), cb_(cb), cr_(cr), rgb_(rgb) {}
  Status BeginFrame(const FrameInfo& info) override;
  Status Rows(const FrameRows& rows) override;
  Status EndFrame() override { return Status::Ok(); }
  const FrameInfo& frame() const { return frame_; }

 private:
  FrameInfo frame_;
  uint8_t *y_, *cb_, *cr_, *rgb_;
};

// How a refocusable file's depth maps to the render's disparity (disparity = scale / depth, in
// working px), and the f-number that reproduces its GFocus blur: the product's own files store
// 1 / disparity, a phone's its own units. `width` is the original's, `working_scale` the
// render's. For every reader of such files (rerender, the camera's page).
struct FileDepthUnits {
  double scale = 1.0;
  float f_number = 2.8f;
};
FileDepthUnits DepthUnitsOf(const RefocusableXmp& xmp, int32_t width, int32_t working_scale);

class Rerenderer {
 public:
  // Reads `path`: its GDepth (RangeInverse or RangeLinear, PNG or JPEG, any size up to the
  // photo's: resampled onto the render's working grid) and the original it refocuses, GImage or,
  // when the file has none, the photo itself (from_primary()).
  Status Load(const char* path);
  // The file's own focus (GFocus: its point, moved to the nearest pixel at its FocalDistance,
  // and the f-number that gives its BlurAtInfinity) into `params`, except what the user chose.
  void StartFromFile(RenderParams* params, bool keep_focus, bool keep_f_number) const;
  bool has_file_focus() const { return has_file_focus_; }
  // The file had no GImage: the starting picture is already blurred where it was not in focus.
  bool from_primary() const { return from_primary_; }
  // Renders and writes `out_path` atomically; `observer` sees every strip before encoding.
  Status Render(const RerenderOptions& options, const char* out_path,
                StripObserver* observer = nullptr);

  ConstPlanarU8 reference() const;
  ConstImageU16 disparity_q8() const;
  int32_t width() const { return width_; }
  int32_t height() const { return height_; }
  int32_t working_scale() const { return scale_; }

 private:
  FocusRegion FocusNear(double point_x, double point_y, double target_q8) const;

  int32_t width_ = 0, height_ = 0, scale_ = 1, depth_w_ = 0, depth_h_ = 0;
  int32_t orientation_ = 0;           // the file's EXIF Orientation, carried into the re-render
  std::vector<uint8_t> y_, cb_, cr_;  // the original as JFIF YCbCr 4:2:0
  std::vector<uint16_t> disp_q8_;
  DisparityRange range_;
  std::vector<uint8_t> original_jpeg_;  // empty when from_primary_: the output has no GImage
  bool from_primary_ = false, has_file_focus_ = false;
  FocusRegion file_focus_;
  float file_f_number_ = 2.8f;
};

}  // namespace lb
