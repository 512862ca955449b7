// Parsing of the command-line values shared by the subcommands. Each parser returns false and
// fills a one-line message when the text is not a valid value.
#pragma once

#include <cstdint>
#include <string>

#include "algo/render/render_stage.h"

namespace lb::cli {

bool ParseInt(const char* text, int32_t lo, int32_t hi, int32_t* out, std::string* error);
bool ParseFloat(const char* text, float lo, float hi, float* out, std::string* error);
// "X,Y" (a point: a small square around it) or "X,Y,W,H" (a rectangle), full-resolution px.
bool ParseFocus(const char* text, FocusRegion* out, std::string* error);
// "disc" or "N-blade" / "polygon:N", e.g. "6-blade", "polygon:9".
bool ParseAperture(const char* text, Aperture* out, std::string* error);
// "WxH".
bool ParseSize(const char* text, int32_t* width, int32_t* height, std::string* error);

// Prints "refocus: <message>" on stderr and returns exit code 1.
int Fail(const char* message);

}  // namespace lb::cli
