// Parsing of the command-line values shared by the subcommands. Each parser returns false and
// fills a one-line message when the text is not a valid value.
#pragma once

#include <getopt.h>

#include <cstdint>
#include <string>
#include <vector>

#include "algo/pipeline/pipeline.h"
#include "algo/render/render_stage.h"

namespace lb::cli {

bool ParseInt(const char* text, int32_t lo, int32_t hi, int32_t* out, std::string* error);
bool ParseFloat(const char* text, float lo, float hi, float* out, std::string* error);
// "MIN,MAX" in px per view step, signed (a converged rig has both signs): -255 <= MIN < MAX
// <= 255, at most 255 apart; Q8.8 out, rounded to nearest.
bool ParseDisparityRange(const char* text, int32_t* lo_q8, int32_t* hi_q8, std::string* error);
// "X,Y" (a point: a small square around it) or "X,Y,W,H" (a rectangle), full-resolution px.
bool ParseFocus(const char* text, FocusRegion* out, std::string* error);
// "disc" or "N-blade" / "polygon:N", e.g. "6-blade", "polygon:9".
bool ParseAperture(const char* text, Aperture* out, std::string* error);
// "auto" or "rectified".
bool ParseGeometry(const char* text, Geometry* out, std::string* error);
// "WxH".
bool ParseSize(const char* text, int32_t* width, int32_t* height, std::string* error);

// The lens and output options `run` and `rerender` share: --focus, --f-number, --aperture,
// --rotation, --curvature, --highlight-threshold, --highlight-gain, --max-radius, --quality.
struct LensOptions {
  RenderParams render;
  int32_t max_radius = 32;
  int quality = 92;
};
extern const char kLensUsage[];  // their lines of --help
// Option ids from kFirstLensOption up belong to the lens options; a command's own ids stay below.
inline constexpr int kFirstLensOption = 1000;
// `own` (without the terminating zero entry) followed by the lens options and the zero entry.
std::vector<option> WithLensOptions(std::initializer_list<option> own);
// Parses lens option `id`; returns false with `error` set for a bad value.
bool ParseLensOption(int id, const char* arg, LensOptions* lens, std::string* error);

// Prints "refocus: <message>" on stderr and returns exit code 1.
int Fail(const char* message);

}  // namespace lb::cli
