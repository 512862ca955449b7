// Re-renders a refocusable JPEG with a new focus or aperture, from the file alone: the stored
// depth map (GDepth) and the all-in-focus original (GImage) go through the same render stage as
// a fresh burst, and the result is written refocusable again. The file is decoded and the render
// begun by RefocusablePhoto, as for the camera's page; the writing is WriteRerendered, also
// theirs. Host-side tool: allocates.
#pragma once

#include <cstdint>
#include <vector>

#include "algo/core/frame.h"
#include "algo/core/image.h"
#include "algo/render/render_stage.h"
#include "firmware/app/job.h"
#include "firmware/app/progress.h"
#include "firmware/app/refocusable_photo.h"
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

// What a re-render writes besides the pixels: the depth the file carried, its confidence, its
// all-in-focus original and its orientation, so the new photo is refocusable again.
struct RerenderSource {
  ConstImageU16 disp_q8;
  ConstImageU8 confidence;  // disp_q8's size; empty when the file had none (the new one has none)
  DisparityRange range;
  const std::vector<uint8_t>* original_jpeg = nullptr;
  int32_t orientation = 0;
  int32_t width = 0, height = 0;
};

// The writing half of every re-render (`refocus rerender` and the web page's engine): `render`
// has begun with `params`; its strips go through `observer` (may be nullptr) into a refocusable
// JPEG (GDepth and Dynamic Depth) written atomically at `out_path`. Allocates the metadata (XMP,
// EXIF, Dynamic Depth's items) while it writes.
// `replace`: whether out_path may be a regular file already (AtomicFile::Commit).
Status WriteRerendered(RenderStage* render, const RenderParams& params,
                       const RerenderSource& source, int quality, const char* software,
                       StripObserver* observer, Progress* progress, const char* out_path,
                       AtomicFile::Replace replace = AtomicFile::Replace::kRegularFile);

// What a re-render of `photo` writes besides the pixels.
RerenderSource SourceOf(const RefocusablePhoto& photo);

class Rerenderer {
 public:
  // Reads `path` (RefocusablePhoto): its depth (GDepth or Dynamic Depth, RangeInverse or
  // RangeLinear, PNG or JPEG, any size up to the photo's: resampled onto the render's working grid)
  // and the original it refocuses, GImage or, when the file has none, the photo itself
  // (from_primary()).
  Status Load(const char* path);
  // The file's own focus (GFocus: its point, moved to the nearest pixel at its FocalDistance,
  // and the f-number that gives its BlurAtInfinity) into `params`, except what the user chose.
  void StartFromFile(RenderParams* params, bool keep_focus, bool keep_f_number) const;
  bool has_file_focus() const { return photo_.has_file_focus(); }
  // The file had no GImage: the starting picture is already blurred where it was not in focus.
  bool from_primary() const { return photo_.from_primary(); }
  // Renders and writes `out_path` atomically; `observer` sees every strip before encoding.
  Status Render(const RerenderOptions& options, const char* out_path,
                StripObserver* observer = nullptr);

  ConstPlanarU8 reference() const { return photo_.reference(); }
  ConstImageU16 disparity_q8() const { return photo_.disparity_q8(); }
  int32_t width() const { return photo_.width(); }
  int32_t height() const { return photo_.height(); }
  int32_t working_scale() const { return photo_.working_scale(); }

 private:
  RefocusablePhoto photo_;  // its buffers grow to each file's needs
};

}  // namespace lb
