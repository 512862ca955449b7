#include "firmware/cli/options.h"

#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/app/focus.h"
#include "firmware/app/size_text.h"

namespace lb::cli {
namespace {

std::string Printf(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string Printf(const char* format, ...) {
  char buf[256];
  va_list args;
  va_start(args, format);
  vsnprintf(buf, sizeof(buf), format, args);
  va_end(args);
  return buf;
}

}  // namespace

bool ParseInt(const char* text, int32_t lo, int32_t hi, int32_t* out, std::string* error) {
  char* end = nullptr;
  errno = 0;
  const long v = strtol(text, &end, 10);
  if (errno || end == text || *end != '\0' || v < lo || v > hi) {
    *error = Printf("'%s' is not a whole number from %d to %d", text, lo, hi);
    return false;
  }
  *out = static_cast<int32_t>(v);
  return true;
}

bool ParseDisparityRange(const char* text, int32_t* lo_q8, int32_t* hi_q8, std::string* error) {
  float lo = 0, hi = 0;
  char tail = 0;
  if (sscanf(text, "%f,%f%c", &lo, &hi, &tail) != 2 || !(lo >= -255) || !(hi > lo) ||
      !(hi <= 255) || hi - lo > 255) {
    *error = std::string("disparity '") + text +
             "' is not MIN,MAX with -255 <= MIN < MAX <= 255, at most 255 apart";
    return false;
  }
  *lo_q8 = static_cast<int32_t>(__builtin_floor(lo * 256.0f + 0.5f));
  *hi_q8 = static_cast<int32_t>(__builtin_floor(hi * 256.0f + 0.5f));
  return true;
}

bool ParseFloat(const char* text, float lo, float hi, float* out, std::string* error) {
  char* end = nullptr;
  errno = 0;
  const float v = strtof(text, &end);
  if (errno || end == text || *end != '\0' || !std::isfinite(v) || v < lo || v > hi) {
    *error = Printf("'%s' is not a number from %g to %g", text, static_cast<double>(lo),
                    static_cast<double>(hi));
    return false;
  }
  *out = v;
  return true;
}

bool ParseFocus(const char* text, FocusRegion* out, std::string* error) {
  int32_t v[4] = {0, 0, 0, 0};
  int n = 0;
  const char* p = text;
  while (n < 4) {
    char* end = nullptr;
    errno = 0;
    const long x = strtol(p, &end, 10);
    if (errno || end == p || x < 0 || x > 65535) break;
    v[n++] = static_cast<int32_t>(x);
    if (*end == '\0') {
      p = end;
      break;
    }
    if (*end != ',') {
      n = -1;
      break;
    }
    p = end + 1;
  }
  if ((n != 2 && n != 4) || *p != '\0' || (n == 4 && (v[2] == 0 || v[3] == 0))) {
    *error = Printf("focus '%s' is neither X,Y nor X,Y,W,H (pixels of the reference image)", text);
    return false;
  }
  if (n == 2) {
    *out = FocusAtPoint(v[0], v[1]);
    if (out->x < 0) out->x = 0;
    if (out->y < 0) out->y = 0;
  } else {
    *out = {v[0], v[1], v[2], v[3]};
  }
  return true;
}

bool ParseAperture(const char* text, Aperture* out, std::string* error) {
  int32_t blades = 0;
  if (strcmp(text, "disc") == 0) {
    out->blades = 0;
    return true;
  }
  const char* num = nullptr;
  std::string t(text);
  if (t.rfind("polygon:", 0) == 0) num = text + 8;
  const size_t dash = t.find("-blade");
  std::string head = dash == std::string::npos ? "" : t.substr(0, dash);
  if (!num && !head.empty() && t.substr(dash) == "-blade") num = head.c_str();
  if (!num || !ParseInt(num, 3, 12, &blades, error)) {
    *error =
        Printf("aperture '%s' is neither 'disc' nor N-blade / polygon:N with N from 3 to 12", text);
    return false;
  }
  out->blades = blades;
  return true;
}

bool ParseGeometry(const char* text, Geometry* out, std::string* error) {
  if (strcmp(text, "auto") == 0) {
    *out = Geometry::kAuto;
  } else if (strcmp(text, "rectified") == 0) {
    *out = Geometry::kRectified;
  } else {
    *error = Printf("geometry '%s' is neither auto nor rectified", text);
    return false;
  }
  return true;
}

bool ParseSize(const char* text, int32_t* width, int32_t* height, std::string* error) {
  if (!ParseSizeText(text, 16, 8192, width, height)) {
    *error = Printf("size '%s' is not WxH between 16x16 and 8192x8192", text);
    return false;
  }
  return true;
}

namespace {
enum LensId {
  kFocus = kFirstLensOption,
  kFNumber,
  kAperture,
  kRotation,
  kCurvature,
  kHighlightThreshold,
  kHighlightGain,
  kMaxRadius,
  kQuality,
};
}  // namespace

const char kLensUsage[] =
    "Lens:\n"
    "  --focus X,Y[,W,H]      point or rectangle to keep sharp (default: the centre)\n"
    "  --f-number N           aperture as on a lens, 1 .. 22 (default 2.8)\n"
    "  --aperture SHAPE       disc (default), or N-blade for a polygonal iris (3..12)\n"
    "  --rotation DEG         rotation of the polygonal iris\n"
    "  --curvature C          blade curvature, 0 (straight) .. 1 (round)\n"
    "  --highlight-threshold T, --highlight-gain G   bright bokeh boost (default off)\n"
    "  --max-radius R         largest blur radius in px (default 32)\n"
    "  --quality Q            JPEG quality 1..100 (default 92)\n";

std::vector<option> WithLensOptions(std::initializer_list<option> own) {
  std::vector<option> all(own);
  all.insert(all.end(),
             {
                 {"focus", required_argument, nullptr, kFocus},
                 {"f-number", required_argument, nullptr, kFNumber},
                 {"aperture", required_argument, nullptr, kAperture},
                 {"rotation", required_argument, nullptr, kRotation},
                 {"curvature", required_argument, nullptr, kCurvature},
                 {"highlight-threshold", required_argument, nullptr, kHighlightThreshold},
                 {"highlight-gain", required_argument, nullptr, kHighlightGain},
                 {"max-radius", required_argument, nullptr, kMaxRadius},
                 {"quality", required_argument, nullptr, kQuality},
                 {nullptr, 0, nullptr, 0},
             });
  return all;
}

bool ParseLensOption(int id, const char* arg, LensOptions* lens, std::string* error) {
  RenderParams& r = lens->render;
  switch (id) {
    case kFocus:
      return ParseFocus(arg, &r.focus, error);
    case kFNumber:
      return ParseFloat(arg, 1.0f, 22.0f, &r.f_number, error);
    case kAperture:
      return ParseAperture(arg, &r.aperture, error);
    case kRotation:
      return ParseFloat(arg, -360.0f, 360.0f, &r.aperture.rotation_deg, error);
    case kCurvature:
      return ParseFloat(arg, 0.0f, 1.0f, &r.aperture.curvature, error);
    case kHighlightThreshold: {
      int32_t t = 255;
      const bool ok = ParseInt(arg, 0, 255, &t, error);
      r.highlight_threshold = static_cast<uint8_t>(t);
      return ok;
    }
    case kHighlightGain:
      return ParseFloat(arg, 1.0f, 8.0f, &r.highlight_gain, error);
    case kMaxRadius:
      return ParseInt(arg, 0, 128, &lens->max_radius, error);
    case kQuality:
      return ParseInt(arg, 1, 100, &lens->quality, error);
    default:
      *error = "unknown option";
      return false;
  }
}

int Fail(const char* message) {
  fprintf(stderr, "refocus: %s\n", message);
  return 1;
}

}  // namespace lb::cli
