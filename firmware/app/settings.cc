#include "firmware/app/settings.h"

#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/app/focus.h"

namespace lb {

bool Why(std::string* why, const char* format, ...) {
  char text[256];
  va_list args;
  va_start(args, format);
  vsnprintf(text, sizeof(text), format, args);
  va_end(args);
  *why = text;
  return false;
}

namespace {

// One run of 1-9 decimal digits (no sign, no spaces) within [lo, hi]; `text` moves past it.
bool Digits(const char** text, int32_t lo, int32_t hi, int32_t* out) {
  const char* p = *text;
  if (*p < '0' || *p > '9') return false;
  char* end = nullptr;
  errno = 0;
  const long long v = strtoll(p, &end, 10);
  if (errno != 0 || end - p > 9 || v < lo || v > hi) return false;
  *out = static_cast<int32_t>(v);
  *text = end;
  return true;
}

// "WxH", each side within [lo, hi].
bool Size(const char* text, int32_t lo, int32_t hi, int32_t* width, int32_t* height) {
  const char* p = text;
  int32_t w = 0, h = 0;
  if (!Digits(&p, lo, hi, &w) || *p++ != 'x' || !Digits(&p, lo, hi, &h) || *p != '\0') {
    return false;
  }
  *width = w;
  *height = h;
  return true;
}

// Up to `n` comma-separated coordinates of 0..65535; returns how many, or -1.
int Coordinates(const char* p, int32_t* v, int n) {
  int got = 0;
  while (got < n) {
    if (!Digits(&p, 0, 65535, &v[got++])) return -1;
    if (*p == '\0') return got;
    if (*p++ != ',') return -1;
  }
  return -1;
}

bool Focus(const char* text, JobOptions* job, std::string* why) {
  int32_t v[4] = {};
  int n = -1;
  if (strcmp(text, "center") == 0) {
    n = 0;
  } else if (strncmp(text, "point ", 6) == 0) {  // refocusd.conf's longer spellings
    n = Coordinates(text + 6, v, 2) == 2 ? 2 : -1;
  } else if (strncmp(text, "region ", 7) == 0) {
    n = Coordinates(text + 7, v, 4) == 4 ? 4 : -1;
  } else {
    n = Coordinates(text, v, 4);
  }
  if (n == 0) {
    job->render.focus = FocusRegion();
  } else if (n == 2) {
    FocusRegion r = FocusAtPoint(v[0], v[1]);
    if (r.x < 0) r.x = 0;  // the square slides inside the photo rather than shrink
    if (r.y < 0) r.y = 0;
    job->render.focus = r;
  } else if (n == 4 && v[2] > 0 && v[3] > 0) {
    job->render.focus = {v[0], v[1], v[2], v[3]};
  } else {
    return Why(why,
               "'%s' is none of: center, X,Y (a point), X,Y,W,H (a rectangle), in pixels of the "
               "photo",
               text);
  }
  return true;
}

bool ApertureShape(const char* text, JobOptions* job, std::string* why) {
  if (strcmp(text, "disc") == 0) {
    job->render.aperture.blades = 0;
    return true;
  }
  const char* p = text;
  const bool polygon = strncmp(p, "polygon:", 8) == 0;
  if (polygon) p += 8;
  int32_t blades = 0;
  if (!Digits(&p, 3, 12, &blades) || strcmp(p, polygon ? "" : "-blade") != 0) {
    return Why(why, "'%s' is none of: disc, N-blade, polygon:N with N from 3 to 12", text);
  }
  job->render.aperture.blades = blades;
  return true;
}

bool Resolution(const char* text, JobOptions* job, std::string* why) {
  if (strcmp(text, "native") == 0) {
    job->sensor.width = job->sensor.height = 0;
    return true;
  }
  if (!Size(text, 16, PipelineConfig::kMaxWidth, &job->sensor.width, &job->sensor.height)) {
    return Why(why, "'%s' is neither native nor WxH between 16x16 and %dx%d", text,
               PipelineConfig::kMaxWidth, PipelineConfig::kMaxHeight);
  }
  return true;
}

bool WorkingSize(const char* text, JobOptions* job, std::string* why) {
  PipelineConfig& p = job->pipeline;
  if (!Size(text, 16, PipelineConfig::kMaxWidth, &p.max_working_width, &p.max_working_height)) {
    return Why(why, "'%s' is not WxH between 16x16 and %dx%d", text, PipelineConfig::kMaxWidth,
               PipelineConfig::kMaxHeight);
  }
  return true;
}

bool GeometryName(const char* text, JobOptions* job, std::string* why) {
  if (strcmp(text, "auto") == 0) {
    job->pipeline.geometry = ViewGeometry::kAuto;
  } else if (strcmp(text, "rectified") == 0) {
    job->pipeline.geometry = ViewGeometry::kRectified;
  } else {
    return Why(why, "'%s' is neither auto nor rectified", text);
  }
  return true;
}

bool Focal35mm(const char* text, JobOptions* job, std::string* why) {
  int32_t mm = 0;
  if (!ParseWholeNumber(text, 0, 2000, &mm, why) || (mm != 0 && mm < 8)) {
    return Why(why, "'%s' is neither 0 (unknown) nor a focal length from 8 to 2000 mm", text);
  }
  job->focal_35mm = mm;
  return true;
}

bool HighlightThreshold(const char* text, JobOptions* job, std::string* why) {
  int32_t t = 0;
  if (!ParseWholeNumber(text, 0, 255, &t, why)) return false;
  job->render.highlight_threshold = static_cast<uint8_t>(t);
  return true;
}

// clang-format off
const Setting kSettings[] = {
  {"focus", nullptr, SettingGroup::kLens, "X,Y[,W,H]",
   "point or rectangle to keep sharp, px of the photo (default: the centre)", Focus},
  {"f-number", nullptr, SettingGroup::kLens, "N", "aperture as on a lens, 1 .. 22 (default 2.8)",
   [](const char* t, JobOptions* j, std::string* w) {
     return ParseRealNumber(t, RenderParams::kMinFNumber, RenderParams::kMaxFNumber,
                            &j->render.f_number, w); }},
  {"aperture", nullptr, SettingGroup::kLens, "SHAPE",
   "disc (default), or N-blade for a polygonal iris (N 3..12)", ApertureShape},
  {"aperture-rotation", "rotation", SettingGroup::kLens, "DEG",
   "rotation of the polygonal iris, -360 .. 360", [](const char* t, JobOptions* j, std::string* w) {
     return ParseRealNumber(t, -360.0f, 360.0f, &j->render.aperture.rotation_deg, w); }},
  {"blade-curvature", "curvature", SettingGroup::kLens, "C",
   "blade curvature, 0 (straight) .. 1 (round)", [](const char* t, JobOptions* j, std::string* w) {
     return ParseRealNumber(t, 0.0f, 1.0f, &j->render.aperture.curvature, w); }},
  {"highlight-threshold", nullptr, SettingGroup::kLens, "T",
   "brightness 0..255 from which bokeh is boosted (default 255: off)", HighlightThreshold},
  {"highlight-gain", nullptr, SettingGroup::kLens, "G", "bokeh boost, 1 .. 8 (default 1)",
   [](const char* t, JobOptions* j, std::string* w) {
     return ParseRealNumber(t, 1.0f, 8.0f, &j->render.highlight_gain, w); }},
  {"max-blur-radius", "max-radius", SettingGroup::kLens, "R",
   "largest blur radius, px of the photo, 0..128 (default 32)",
   [](const char* t, JobOptions* j, std::string* w) {
     return ParseWholeNumber(t, 0, 128, &j->pipeline.max_blur_radius, w); }},
  {"quality", nullptr, SettingGroup::kLens, "Q", "JPEG quality 1..100 (default 92)",
   [](const char* t, JobOptions* j, std::string* w) {
     return ParseWholeNumber(t, 1, 100, &j->quality, w); }},
  {"resolution", "size", SettingGroup::kBurst, "WxH",
   "frame size, 16x16 .. 8192x8192, or native (default 1280x960)", Resolution},
  {"frames", nullptr, SettingGroup::kBurst, "N", "burst length, 2..16 (default 5)",
   [](const char* t, JobOptions* j, std::string* w) {
     return ParseWholeNumber(t, 2, PipelineConfig::kMaxFrames, &j->sensor.frames, w); }},
  {"geometry", nullptr, SettingGroup::kDepth, "G",
   "auto: a handheld burst, its motion estimated (default); rectified: equally spaced views, "
   "left to right", GeometryName},
  {"focal-35mm", nullptr, SettingGroup::kDepth, "F",
   "the lens as a 35 mm equivalent focal length, 8..2000 (default 0: the sensor's or the "
   "files' EXIF, else estimated from the frames)", Focal35mm},
  {"labels", nullptr, SettingGroup::kDepth, "N", "depth labels, 2..256 (default 64)",
   [](const char* t, JobOptions* j, std::string* w) {
     return ParseWholeNumber(t, 2, 256, &j->pipeline.labels, w); }},
  {"working-size", nullptr, SettingGroup::kDepth, "WxH",
   "working resolution for depth: at most W x H pixels, neither side over the longer of W and "
   "H, 16x16 .. 8192x8192 (default 680x510: a sixth of a 12 MP frame's side)",
   WorkingSize},
  {"threads", nullptr, SettingGroup::kWork, "N",
   "worker threads for depth and render, 1..16, or 0: one per core (default 0); the photo is "
   "the same whatever the number",
   [](const char* t, JobOptions* j, std::string* w) {
     return ParseWholeNumber(t, 0, kMaxWorkers, &j->threads, w); }},
};
// clang-format on
constexpr int kCount = sizeof(kSettings) / sizeof(kSettings[0]);

// `a` and `b` equal when dashes and underscores are taken as one.
bool SameName(const char* a, const char* b) {
  for (; *a != '\0' && *b != '\0'; ++a, ++b) {
    const char x = *a == '_' ? '-' : *a, y = *b == '_' ? '-' : *b;
    if (x != y) return false;
  }
  return *a == *b;
}

}  // namespace

bool ParseWholeNumber(const char* text, int32_t lo, int32_t hi, int32_t* out, std::string* why) {
  char* end = nullptr;
  errno = 0;
  const long long v = strtoll(text, &end, 10);
  if (errno != 0 || end == text || *end != '\0' || v < lo || v > hi) {
    return Why(why, "'%s' is not a whole number from %d to %d", text, lo, hi);
  }
  *out = static_cast<int32_t>(v);
  return true;
}

bool ParseRealNumber(const char* text, float lo, float hi, float* out, std::string* why) {
  char* end = nullptr;
  errno = 0;
  const float v = strtof(text, &end);
  // Below the smallest float strtof says ERANGE, yet the number is as good as 0 (or the
  // denormal it returns): the range decides.
  const bool underflow = errno == ERANGE && std::fabs(v) <= FLT_MIN;
  if ((errno != 0 && !underflow) || end == text || *end != '\0' || !std::isfinite(v) || v < lo ||
      v > hi) {
    return Why(why, "'%s' is not a number from %g to %g", text, static_cast<double>(lo),
               static_cast<double>(hi));
  }
  *out = v;
  return true;
}

const Setting* SettingAt(int i) { return i >= 0 && i < kCount ? &kSettings[i] : nullptr; }

const Setting* FindSetting(const char* name) {
  for (const Setting& s : kSettings) {
    if (SameName(name, s.name) || (s.alias != nullptr && SameName(name, s.alias))) return &s;
  }
  return nullptr;
}

std::string SettingsHelp(SettingGroup group) {
  constexpr size_t kColumn = 25, kWidth = 96;  // the commands' usage texts align so
  std::string out;
  for (const Setting& s : kSettings) {
    if (s.group != group) continue;
    std::string line = std::string("  --") + s.name + " " + s.value;
    line += line.size() < kColumn - 1 ? std::string(kColumn - line.size(), ' ') : " ";
    for (const char* word = s.help; *word != '\0';) {
      const char* end = strchr(word, ' ');
      const size_t n = end ? static_cast<size_t>(end - word) : strlen(word);
      if (line.size() + n > kWidth) {
        while (line.back() == ' ') line.pop_back();
        out += line + "\n";
        line.assign(kColumn, ' ');
      }
      line.append(word, n);
      word += n;
      if (*word == ' ') {
        line += ' ';
        ++word;
      }
    }
    out += line + "\n";
  }
  return out;
}

}  // namespace lb
