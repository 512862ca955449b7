#include "firmware/daemon/config.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/app/focus.h"
#include "firmware/app/size_text.h"

namespace lb {
namespace {

constexpr size_t kMaxFileBytes = 64 * 1024;
constexpr size_t kMaxText = 63;  // make, model

using Why = std::string;

bool Fail(Why* why, const char* format, ...) __attribute__((format(printf, 2, 3)));
bool Fail(Why* why, const char* format, ...) {
  char text[200];
  va_list args;
  va_start(args, format);
  vsnprintf(text, sizeof(text), format, args);
  va_end(args);
  *why = text;
  return false;
}

bool Int(const char* v, int64_t lo, int64_t hi, int64_t* out, Why* why) {
  char* end = nullptr;
  errno = 0;
  const long long x = strtoll(v, &end, 10);
  if (errno || end == v || *end != '\0' || x < lo || x > hi) {
    return Fail(why, "'%s' is not a whole number from %lld to %lld", v, static_cast<long long>(lo),
                static_cast<long long>(hi));
  }
  *out = x;
  return true;
}

bool Int32(const char* v, int32_t lo, int32_t hi, int32_t* out, Why* why) {
  int64_t x = 0;
  if (!Int(v, lo, hi, &x, why)) return false;
  *out = static_cast<int32_t>(x);
  return true;
}

bool Float(const char* v, float lo, float hi, float* out, Why* why) {
  char* end = nullptr;
  errno = 0;
  const float x = strtof(v, &end);
  if (errno || end == v || *end != '\0' || !std::isfinite(x) || x < lo || x > hi) {
    return Fail(why, "'%s' is not a number from %g to %g", v, static_cast<double>(lo),
                static_cast<double>(hi));
  }
  *out = x;
  return true;
}

bool Size(const char* v, int32_t* w, int32_t* h, Why* why) {
  if (!ParseSizeText(v, 16, 8192, w, h)) {
    return Fail(why, "'%s' is not WxH between 16x16 and 8192x8192", v);
  }
  return true;
}

bool Text(const char* v, std::string* out, Why* why) {
  if (strlen(v) > kMaxText) return Fail(why, "longer than %zu characters", kMaxText);
  *out = v;
  return true;
}

// "center", "point X,Y" or "region X,Y,W,H" in full-resolution pixels.
bool Focus(const char* v, FocusRegion* out, Why* why) {
  int x = 0, y = 0, w = 0, h = 0;
  char tail = 0;
  if (strcmp(v, "center") == 0) {
    *out = FocusRegion();
  } else if (sscanf(v, "point %d,%d%c", &x, &y, &tail) == 2 && x >= 0 && y >= 0) {
    *out = FocusAtPoint(x, y);  // the same square as refocus --focus X,Y
  } else if (sscanf(v, "region %d,%d,%d,%d%c", &x, &y, &w, &h, &tail) == 4 && x >= 0 && y >= 0 &&
             w > 0 && h > 0) {
    *out = {x, y, w, h};
  } else {
    return Fail(why, "'%s' is none of: center, point X,Y, region X,Y,W,H", v);
  }
  return true;
}

bool ApertureShape(const char* v, Aperture* out, Why* why) {
  int blades = 0;
  char tail = 0;
  if (strcmp(v, "disc") == 0) {
    out->blades = 0;
  } else if (sscanf(v, "%d-blade%c", &blades, &tail) == 1 && blades >= 3 && blades <= 12 &&
             strchr(v, ' ') == nullptr) {
    out->blades = blades;
  } else {
    return Fail(why, "'%s' is neither disc nor N-blade with N from 3 to 12", v);
  }
  return true;
}

struct Key {
  const char* name;
  bool (*parse)(const char* v, DaemonConfig* c, Why* why);
};

const Key kKeys[] = {
    {"backend",
     [](const char* v, DaemonConfig* c, Why* why) {
       for (Backend b : {Backend::kV4l2, Backend::kLibcamera, Backend::kSynthetic}) {
         if (strcmp(v, BackendName(b)) == 0) {
           c->backend = b;
           return true;
         }
       }
       return Fail(why, "'%s' is none of: v4l2, libcamera, synthetic", v);
     }},
    {"device",
     [](const char* v, DaemonConfig* c, Why*) {
       c->device = strcmp(v, "auto") == 0 ? "" : v;
       return true;
     }},
    {"resolution",
     [](const char* v, DaemonConfig* c, Why* why) {
       if (strcmp(v, "native") == 0) {
         c->width = c->height = 0;
         return true;
       }
       return Size(v, &c->width, &c->height, why);
     }},
    {"frames", [](const char* v, DaemonConfig* c,
                  Why* why) { return Int32(v, 2, PipelineConfig::kMaxFrames, &c->frames, why); }},
    {"fps",
     [](const char* v, DaemonConfig* c, Why* why) { return Int32(v, 0, 240, &c->fps, why); }},
    {"frame_timeout_ms", [](const char* v, DaemonConfig* c,
                            Why* why) { return Int32(v, 100, 60000, &c->frame_timeout_ms, why); }},
    {"seed",
     [](const char* v, DaemonConfig* c, Why* why) {
       int64_t x = 0;
       if (!Int(v, 0, INT32_MAX, &x, why)) return false;
       c->seed = static_cast<uint64_t>(x);
       return true;
     }},
    {"button",
     [](const char* v, DaemonConfig* c, Why*) {
       c->button = v;
       return true;
     }},
    {"debounce_ms", [](const char* v, DaemonConfig* c,
                       Why* why) { return Int32(v, 0, 500, &c->debounce_ms, why); }},
    {"busy_press",
     [](const char* v, DaemonConfig* c, Why* why) {
       if (strcmp(v, "queue") == 0) {
         c->busy = BusyPolicy::kQueue;
       } else if (strcmp(v, "refuse") == 0) {
         c->busy = BusyPolicy::kRefuse;
       } else {
         return Fail(why, "'%s' is neither queue nor refuse", v);
       }
       return true;
     }},
    {"capture_retries", [](const char* v, DaemonConfig* c,
                           Why* why) { return Int32(v, 0, 5, &c->capture_retries, why); }},
    {"output_dir",
     [](const char* v, DaemonConfig* c, Why* why) {
       // Room for "/IMG_YYYYMMDD_HHMMSS_NNNN.jpg" and the temporary's suffix within a path.
       if (strlen(v) > 900) return Fail(why, "longer than 900 characters");
       c->output_dir = v;
       return true;
     }},
    {"quality",
     [](const char* v, DaemonConfig* c, Why* why) { return Int32(v, 1, 100, &c->quality, why); }},
    {"make", [](const char* v, DaemonConfig* c, Why* why) { return Text(v, &c->make, why); }},
    {"model", [](const char* v, DaemonConfig* c, Why* why) { return Text(v, &c->model, why); }},
    {"labels",
     [](const char* v, DaemonConfig* c, Why* why) { return Int32(v, 2, 256, &c->labels, why); }},
    {"geometry",
     [](const char* v, DaemonConfig* c, Why* why) {
       if (strcmp(v, "auto") == 0) {
         c->geometry = Geometry::kAuto;
       } else if (strcmp(v, "rectified") == 0) {
         c->geometry = Geometry::kRectified;
       } else {
         return Fail(why, "'%s' is neither auto nor rectified", v);
       }
       return true;
     }},
    {"focal_35mm",
     [](const char* v, DaemonConfig* c, Why* why) {
       const bool ok = Int32(v, 0, 2000, &c->focal_35mm, why);
       if (ok && c->focal_35mm != 0 && c->focal_35mm < 8) return Fail(why, "%s mm is no lens", v);
       return ok;
     }},
    {"working_size", [](const char* v, DaemonConfig* c,
                        Why* why) { return Size(v, &c->working_width, &c->working_height, why); }},
    {"focus",
     [](const char* v, DaemonConfig* c, Why* why) { return Focus(v, &c->render.focus, why); }},
    {"f_number", [](const char* v, DaemonConfig* c,
                    Why* why) { return Float(v, 1.0f, 22.0f, &c->render.f_number, why); }},
    {"aperture", [](const char* v, DaemonConfig* c,
                    Why* why) { return ApertureShape(v, &c->render.aperture, why); }},
    {"aperture_rotation",
     [](const char* v, DaemonConfig* c, Why* why) {
       return Float(v, -360.0f, 360.0f, &c->render.aperture.rotation_deg, why);
     }},
    {"blade_curvature",
     [](const char* v, DaemonConfig* c, Why* why) {
       return Float(v, 0.0f, 1.0f, &c->render.aperture.curvature, why);
     }},
    {"highlight_threshold",
     [](const char* v, DaemonConfig* c, Why* why) {
       int32_t t = 0;
       if (!Int32(v, 0, 255, &t, why)) return false;
       c->render.highlight_threshold = static_cast<uint8_t>(t);
       return true;
     }},
    {"highlight_gain",
     [](const char* v, DaemonConfig* c, Why* why) {
       return Float(v, 1.0f, 8.0f, &c->render.highlight_gain, why);
     }},
    {"max_blur_radius", [](const char* v, DaemonConfig* c,
                           Why* why) { return Int32(v, 0, 128, &c->max_blur_radius, why); }},
    {"log_level",
     [](const char* v, DaemonConfig* c, Why* why) {
       if (ParseLogLevel(v, &c->log_level)) return true;
       return Fail(why, "'%s' is none of: debug, info, warning, error", v);
     }},
};
constexpr int kKeyCount = sizeof(kKeys) / sizeof(kKeys[0]);

void Trim(std::string* s) {
  const char* space = " \t\r";
  const size_t first = s->find_first_not_of(space);
  if (first == std::string::npos) {
    s->clear();
    return;
  }
  s->erase(s->find_last_not_of(space) + 1);
  s->erase(0, first);
}

}  // namespace

const char* ConfigKeyName(int i) { return i >= 0 && i < kKeyCount ? kKeys[i].name : nullptr; }

const char* BackendName(Backend backend) {
  switch (backend) {
    case Backend::kV4l2:
      return "v4l2";
    case Backend::kLibcamera:
      return "libcamera";
    case Backend::kSynthetic:
      return "synthetic";
  }
  return "?";
}

Status ParseConfig(const char* name, const char* text, DaemonConfig* config) {
  int first_line[kKeyCount] = {};
  int line_no = 0;
  int focus_line = 0;
  const char* p = text;
  while (*p != '\0') {
    ++line_no;
    const char* eol = strchr(p, '\n');
    std::string line(p, eol ? static_cast<size_t>(eol - p) : strlen(p));
    p = eol ? eol + 1 : p + line.size();
    Trim(&line);
    if (line.empty() || line[0] == '#') continue;
    const size_t eq = line.find('=');
    if (eq == std::string::npos) {
      return Status(Code::kInvalidArgument, "%s:%d: '%.60s' is not 'key = value'", name, line_no,
                    line.c_str());
    }
    std::string key = line.substr(0, eq), value = line.substr(eq + 1);
    Trim(&key);
    Trim(&value);
    int k = 0;
    while (k < kKeyCount && key != kKeys[k].name) ++k;
    if (k == kKeyCount) {
      return Status(Code::kInvalidArgument, "%s:%d: unknown key '%.60s'", name, line_no,
                    key.c_str());
    }
    if (first_line[k] != 0) {
      return Status(Code::kInvalidArgument, "%s:%d: %s is already set on line %d", name, line_no,
                    kKeys[k].name, first_line[k]);
    }
    first_line[k] = line_no;
    if (value.empty()) {
      return Status(Code::kInvalidArgument, "%s:%d: %s has no value", name, line_no, kKeys[k].name);
    }
    Why why;
    if (!kKeys[k].parse(value.c_str(), config, &why)) {
      return Status(Code::kInvalidArgument, "%s:%d: %s: %s", name, line_no, kKeys[k].name,
                    why.c_str());
    }
    if (strcmp(kKeys[k].name, "focus") == 0) focus_line = line_no;
  }
  const FocusRegion& f = config->render.focus;
  if (config->width > 0 && f.width > 0 &&
      (f.x + f.width > config->width || f.y + f.height > config->height)) {
    return Status(Code::kInvalidArgument, "%s:%d: focus lies outside the %dx%d picture", name,
                  focus_line, config->width, config->height);
  }
  return Status::Ok();
}

Status LoadConfig(const char* path, DaemonConfig* config) {
  FILE* f = fopen(path, "rbe");
  if (f == nullptr) {
    const int err = errno;
    return Status(err == ENOENT ? Code::kNotFound : Code::kIoError, "%s: cannot open: %s", path,
                  strerror(err));
  }
  std::string text(kMaxFileBytes + 1, '\0');
  const size_t got = fread(text.data(), 1, text.size(), f);
  const bool failed = ferror(f) != 0;
  fclose(f);
  if (failed) return Status(Code::kIoError, "%s: read error", path);
  if (got > kMaxFileBytes) {
    return Status(Code::kInvalidArgument, "%s: larger than %zu bytes", path, kMaxFileBytes);
  }
  text.resize(got);
  if (text.find('\0') != std::string::npos) {
    return Status(Code::kInvalidArgument, "%s: not a text file (holds a NUL byte)", path);
  }
  return ParseConfig(path, text.c_str(), config);
}

JobOptions MakeJobOptions(const DaemonConfig& config) {
  JobOptions o;
  o.sensor.width = config.width;
  o.sensor.height = config.height;
  o.sensor.frames = config.frames;
  o.sensor.timeout_ms = config.frame_timeout_ms;
  o.pipeline.reference = -1;  // the middle frame
  o.pipeline.labels = config.labels;
  o.pipeline.geometry = config.geometry;
  o.focal_35mm = config.focal_35mm;
  o.pipeline.max_working_width = config.working_width;
  o.pipeline.max_working_height = config.working_height;
  o.pipeline.max_blur_radius = config.max_blur_radius;
  o.render = config.render;
  o.quality = config.quality;
  o.make = config.make.c_str();
  o.model = config.model.c_str();
  o.software = "refocusd";
  return o;
}

}  // namespace lb
