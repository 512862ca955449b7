// RefocusEngine: the camera's own re-render of a refocusable photo (the web page's tap to
// refocus), in memory sized once. Configure takes the largest photo the camera makes and sizes
// every buffer then: the file's bytes (also the output JPEG's, once the file is decoded), the
// reassembled extended XMP, the all-in-focus original (JPEG bytes and YCbCr 4:2:0 planes), the
// depth map, a downscaled copy of both for previews, the readers' strip and the render arenas.
// Load decodes as `refocus rerender` does (RefocusablePhoto: the same files open, phones' Lens
// Blur files among them) into those buffers. Load, RenderPreview, RenderFull allocate nothing after
// Configure (the codec libraries' own scratch memory aside), so the daemon's memory stays flat
// however the page is used; Save shares `refocus rerender`'s writing code (WriteRerendered), which
// builds the file's metadata on the heap and frees it.
//
// The camera comes first: between strips every render waits while `camera_busy` is set, so a
// capture is slowed by at most one strip of web work.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "algo/core/status.h"
#include "algo/render/render_stage.h"
#include "firmware/app/refocusable_photo.h"
#include "firmware/platform/arena_block.h"
#include "firmware/refocusable/depth_encoding.h"
#include "firmware/refocusable/refocusable_reader.h"

namespace lb {

class JpegWriter;
class WorkerPool;

struct RefocusEngineConfig {
  // The largest photo the camera makes (stored pixels); a photo of these sides the other way
  // round (a phone's portrait) opens too.
  int32_t max_width = 0;
  int32_t max_height = 0;
  int32_t threads = 1;  // as JobOptions::threads (0: one per core)
  int32_t max_blur_radius = 32;
  int32_t preview_side = 1024;  // a preview's longer side, at most
  int quality = 92;
  int preview_quality = 85;
  // The largest file Load accepts; 0: one and a half bytes per pixel of the largest photo and
  // 1 MiB, its XMP (the original and the depth, base64) at most one byte per pixel and 1 MiB. The
  // camera's photo holds the original three times (the photo itself, GImage, Dynamic Depth's
  // Original item) and the depth twice.
  size_t max_file_bytes = 0;
  // The largest depth map of another writer's photo (a phone's); the map the camera's own photos
  // carry at max_width x max_height (Pipeline::MapScale) is always taken.
  int32_t max_depth_pixels = 1 << 20;
};

// The loaded photo, in stored pixels (before its EXIF orientation is applied).
struct EnginePhoto {
  int32_t width = 0, height = 0;
  int32_t orientation = 0;  // EXIF 1..8, 0 when the file records none
  int32_t working_scale = 1;
  int32_t preview_width = 0, preview_height = 0;
  // The focus and f-number it was rendered with (GFocus; an f-number estimated from its blur at
  // infinity), a focus point as FocusAtPoint at full size.
  RenderParams current;
  // Per mille of its depth that the file's confidence map calls a guess
  // (Pipeline::GuessPermille); -1 when the file carries no confidence map.
  int32_t guess_permille = -1;
};

class RefocusEngine {
 public:
  RefocusEngine();
  ~RefocusEngine();
  RefocusEngine(const RefocusEngine&) = delete;
  RefocusEngine& operator=(const RefocusEngine&) = delete;

  // Sizes everything and starts the render workers (they inherit the caller's scheduling
  // priority: call it on the thread that will render).
  Status Configure(const RefocusEngineConfig& config);
  // Polled between strips (borrowed; nullptr: never wait).
  void set_camera_busy(const std::atomic<bool>* busy) { camera_busy_ = busy; }

  // Reads a refocusable JPEG. kOutOfMemory: larger than the engine was sized for; kUnsupported /
  // kNotFound / kCorruptData: not a photo the engine can refocus (no depth, no original, ...).
  // After a failure nothing is loaded.
  Status Load(const char* path);
  bool loaded() const { return loaded_; }
  const EnginePhoto& photo() const { return photo_; }

  // `params.focus` in full-size stored pixels. The JPEG (no EXIF unless the photo is turned) is
  // output() until the next call.
  Status RenderPreview(const RenderParams& params);
  Status RenderFull(const RenderParams& params);
  const uint8_t* output() const { return scratch_.data(); }
  size_t output_size() const { return output_size_; }

  // Renders full size and writes a new refocusable photo at `out_path` (atomic-write rule; never
  // over an existing file).
  Status Save(const RenderParams& params, const char* out_path);

  // Bytes reserved by Configure (buffers and arenas).
  size_t reserved_bytes() const { return reserved_bytes_; }
  // Strips during which a render waited for the camera (tests).
  int64_t paused_strips() const { return paused_strips_; }

 private:
  Status LoadFile(const char* path);
  Status Decode(const char* path, size_t size);
  Status MakePreviewInputs();
  Status RenderInto(RenderStage* stage, const RenderParams& params, bool preview);
  void WaitForCamera();

  RefocusEngineConfig config_;
  bool configured_ = false, loaded_ = false;
  const std::atomic<bool>* camera_busy_ = nullptr;
  int64_t paused_strips_ = 0;
  size_t reserved_bytes_ = 0;
  EnginePhoto photo_;

  // The file's bytes while it loads, then the output JPEG (capacity kept: never reallocated).
  std::vector<uint8_t> scratch_;
  size_t output_size_ = 0;
  RefocusablePhoto file_;  // the decoded photo, in buffers Configure sized
  // Preview inputs: the original box-filtered by preview_step_, and the disparity at the
  // preview's working size (or the full map when its scale divides by the step).
  int32_t preview_step_ = 1, preview_scale_ = 1, preview_dw_ = 0, preview_dh_ = 0;
  std::vector<uint8_t> py_, pcb_, pcr_;
  std::vector<uint16_t> pdisp_q8_;
  const uint16_t* preview_disp_ = nullptr;

  ArenaBlock full_block_, preview_block_;
  size_t full_bytes_ = 0, preview_bytes_ = 0;
  std::unique_ptr<RenderStage> full_, preview_;
  std::unique_ptr<WorkerPool> pool_;
  std::unique_ptr<JpegWriter> writer_;  // made once: its constructor allocates
};

}  // namespace lb
