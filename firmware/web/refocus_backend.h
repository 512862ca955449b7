// What the web side asks of the camera's renderer: the HTTP handlers (web_server, routes) call
// this. refocusd gives the server EngineBackend (engine_backend.h), a fixed-memory engine on one
// low-priority render thread that yields to the camera; tests give it a fake.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/status.h"
#include "algo/render/render_stage.h"

namespace lb {

// The page's choice, in the photo's own (EXIF-oriented, as displayed) pixel frame, normalised to
// 0..1 so a tap on a scaled image means the same place at any size. A tap is a zero-size
// rectangle (x0 == x1, y0 == y1): it means FocusAtPoint at full size.
struct RefocusParams {
  float x0 = 0.5f, y0 = 0.5f, x1 = 0.5f, y1 = 0.5f;
  float f_number = 2.8f;  // RenderParams::kMinFNumber .. kMaxFNumber
  Aperture aperture;      // shape: disc or polygon (blades)
};

struct PhotoInfo {
  int32_t width = 0, height = 0;  // as displayed (after EXIF orientation)
  bool refocusable = false;       // has GDepth and GImage: the page can refocus it
  RefocusParams current;          // the focus and aperture it was rendered with (from its XMP)
  // Most of its depth is a guess, as its confidence map says (Pipeline::kRetakePermille): a
  // flat or textureless scene, whose blur may fall in the wrong places.
  bool depth_guess = false;
};

// A growable output the caller owns and reuses (its capacity is kept between calls, so a
// steady stream of requests does not grow memory).
class ByteSink {
 public:
  virtual ~ByteSink() = default;
  virtual bool Append(const uint8_t* data, size_t size) = 0;  // false: over its bound
};

class RefocusBackend {
 public:
  virtual ~RefocusBackend() = default;
  // Longest side of a preview, px (the page shows the preview scaled).
  static constexpr int32_t kPreviewWidth = 1024;

  // `path` is a validated regular file inside the photo folder (the server checked it). Each call
  // may wait for the render thread; kBusy when its bounded queue is full or the camera is
  // taking a photo longer than the call may wait, kUnsupported for a photo it cannot refocus.
  virtual Status Describe(const char* path, PhotoInfo* info) = 0;
  // A JPEG at most kPreviewWidth px on its longer side (preview) or full size.
  virtual Status Render(const char* path, const RefocusParams& params, bool preview,
                        ByteSink* jpeg) = 0;
  // Renders full size and writes a new refocusable photo at `out_path` (absent; the atomic-write
  // rule; the original is never touched).
  virtual Status Save(const char* path, const RefocusParams& params, const char* out_path) = 0;
  // Whether the camera is taking a photo now: the page's other work (thumbnails) waits for it.
  virtual bool CameraBusy() const { return false; }
};

}  // namespace lb
