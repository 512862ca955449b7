// RefocusablePhoto: a refocusable JPEG decoded for a re-render, and the render begun on it. The
// one road from such a file to the render stage, for `refocus rerender` (Rerenderer) and the
// camera's page (RefocusEngine): the same reader (GDepth, GImage, GFocus, Dynamic Depth), the
// same depth image in any colour type, the same depth units (the product's 1 / px or a phone's
// own), the same working grid (a map of another size resampled onto it, its confidence with it)
// and the same focus.
//
// Memory: Configure sizes every buffer once for the largest photo (the engine: nothing is
// allocated after it, the codec libraries' own scratch aside, and a larger file is
// kOutOfMemory). Without Configure the buffers grow to what each file needs (host tools).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "algo/core/arena.h"
#include "algo/core/frame.h"
#include "algo/core/image.h"
#include "algo/core/status.h"
#include "algo/core/task_runner.h"
#include "algo/render/render_stage.h"
#include "firmware/refocusable/depth_encoding.h"
#include "firmware/refocusable/refocusable_reader.h"

namespace lb {

struct RefocusableLimits {
  // The original, stored pixels, either way round: a portrait photo on a landscape camera fits.
  int32_t max_width = 0;
  int32_t max_height = 0;
  size_t max_file_bytes = 0;
  int32_t max_depth_pixels = 1 << 20;  // the depth image as stored
};

// How a refocusable file's depth maps to the render's disparity (disparity = scale / depth, in
// working px), and the f-number that reproduces its GFocus blur: the product's own files store
// 1 / disparity, a phone's its own units. `width` is the original's, `working_scale` the
// render's.
struct FileDepthUnits {
  double scale = 1.0;
  float f_number = 2.8f;
};
FileDepthUnits DepthUnitsOf(const RefocusableFields& file, int32_t width, int32_t working_scale);

class RefocusablePhoto {
 public:
  // Sizes every buffer for files up to `limits` (allocates; see above).
  Status Configure(const RefocusableLimits& limits);
  size_t reserved_bytes() const { return reserved_bytes_; }

  // Decodes a refocusable JPEG's bytes (borrowed for the call only: the caller may reuse them
  // after). `name` starts every message. After a failure nothing is decoded (width() is 0).
  Status Decode(const uint8_t* bytes, size_t size, const char* name);

  int32_t width() const { return width_; }
  int32_t height() const { return height_; }
  int32_t working_scale() const { return scale_; }
  int32_t orientation() const { return orientation_; }  // EXIF 1..8, 0 when none
  // The file had no GImage: the photo itself is the original, already blurred where it was not
  // in focus, and a re-render carries no GImage either.
  bool from_primary() const { return from_primary_; }
  // The file's own focus (GFocus: its point, moved to the nearest pixel at its FocalDistance)
  // and the f-number that gives its BlurAtInfinity.
  bool has_file_focus() const { return has_file_focus_; }
  const FocusRegion& file_focus() const { return file_focus_; }
  float file_f_number() const { return file_f_number_; }

  ConstPlanarU8 reference() const;  // the original, YCbCr 4:2:0
  ConstImageU16 disparity_q8() const;
  // How sure each pixel of disparity_q8() is (0..255, 255: sure; its size): the file's confidence
  // map (GDepth:Confidence or Dynamic Depth's item), so that a re-render carries it on. Empty
  // when the file has none, the reader ignored it, or its pixels do not decode.
  ConstImageU8 confidence() const;
  const DisparityRange& range() const { return range_; }
  // The all-in-focus original's JPEG bytes; empty when from_primary().
  const std::vector<uint8_t>& original_jpeg() const { return original_; }

  // The render stage's configuration for this photo at full size.
  RenderConfig RenderConfigFor(int32_t max_blur_radius, int32_t workers) const;
  // Configures `stage` for RenderConfigFor in `arena` (at least its RequiredBytes), hands it
  // `runner` (borrowed) and begins the render with `params`.
  Status BeginRender(const RenderConfig& config, Arena& arena, TaskRunner* runner,
                     const RenderParams& params, RenderStage* stage) const;

 private:
  class Memory;
  template <typename T>
  bool Fit(std::vector<T>* v, size_t count);
  Status DecodeOriginal(const uint8_t* jpeg, size_t size, const char* name, const char* what);
  Status DecodeDepth(const RefocusableFields& f, const char* name);
  void DecodeConfidence(const RefocusableFields& f, const char* name, int32_t dw, int32_t dh);
  FocusRegion FocusNear(double point_x, double point_y, double target_q8) const;

  bool fixed_ = false;  // Configure sized the buffers: they never grow
  size_t reserved_bytes_ = 0;
  int32_t max_side_ = kMaxFrameSide;
  int32_t width_ = 0, height_ = 0, scale_ = 1, depth_w_ = 0, depth_h_ = 0;
  int32_t orientation_ = 0;
  int depth_bits_ = 16;  // the stored depth image's values
  bool from_primary_ = false, has_file_focus_ = false, has_confidence_ = false;
  FocusRegion file_focus_;
  float file_f_number_ = 2.8f;
  DisparityRange range_;

  std::vector<ExtendedXmpChunk> chunks_;   // the reader's extended-XMP chunk descriptors
  std::vector<uint8_t> extended_;          // the reassembled extended XMP
  std::vector<uint8_t> depth_image_;       // GDepth:Data, base64-decoded (PNG or JPEG)
  std::vector<uint8_t> confidence_image_;  // GDepth:Confidence, base64-decoded
  std::vector<uint8_t> original_;          // GImage:Data, the all-in-focus JPEG
  std::vector<uint8_t> strip_;             // the image readers' rows
  std::vector<uint8_t> rgb_rows_;          // two RGB rows of the original, for its chroma
  std::vector<uint8_t> y_, cb_, cr_;
  std::vector<uint16_t> depth_values_, depth_disp_;  // the image as stored, as disparity
  std::vector<uint16_t> disp_q8_;                    // on the working grid
  std::vector<uint8_t> confidence_;                  // on the working grid
};

}  // namespace lb
