#include "firmware/daemon/config.h"

#include <arpa/inet.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "firmware/app/focus.h"
#include "firmware/app/settings.h"

namespace lb {
namespace {

constexpr size_t kMaxFileBytes = 64 * 1024;
constexpr size_t kMaxText = 63;  // make, model

bool Text(const char* v, std::string* out, std::string* why) {
  if (strlen(v) > kMaxText) return Why(why, "longer than %zu characters", kMaxText);
  *out = v;
  return true;
}

// `off`, or ADDRESS:PORT with a numeric IPv4 address or a bracketed IPv6 one ([::1]:8080).
bool WebAddress(const char* v, DaemonConfig* c, std::string* why) {
  if (strcmp(v, "off") == 0) {
    c->web_address.clear();
    c->web_port = 0;
    return true;
  }
  const char* colon = strrchr(v, ':');
  if (colon == nullptr) return Why(why, "'%s' is neither off nor ADDRESS:PORT", v);
  std::string host(v, static_cast<size_t>(colon - v));
  bool v6 = false;
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
    v6 = true;
  }
  unsigned char addr[16];
  if (inet_pton(v6 ? AF_INET6 : AF_INET, host.c_str(), addr) != 1) {
    return Why(why, "'%s' is not a numeric %s address (e.g. 0.0.0.0:8080 or [::]:8080)",
               host.c_str(), v6 ? "IPv6" : "IPv4");
  }
  std::string port_why;
  int32_t port = 0;
  if (!ParseWholeNumber(colon + 1, 0, 65535, &port, &port_why)) {
    return Why(why, "port: %s", port_why.c_str());
  }
  // The kernel would pick another port at every start, where no browser could find the page.
  if (port == 0) return Why(why, "port 0 is not a port a browser can find; name one (e.g. 8080)");
  c->web_address = host;
  c->web_port = port;
  return true;
}

struct Key {
  const char* name;
  bool (*parse)(const char* v, DaemonConfig* c, std::string* why);
};

const Key kKeys[] = {
    {"backend",
     [](const char* v, DaemonConfig* c, std::string* why) {
       for (Backend b : {Backend::kV4l2, Backend::kLibcamera, Backend::kSynthetic}) {
         if (strcmp(v, BackendName(b)) == 0) {
           c->backend = b;
           return true;
         }
       }
       return Why(why, "'%s' is none of: v4l2, libcamera, synthetic", v);
     }},
    {"device",
     [](const char* v, DaemonConfig* c, std::string*) {
       c->device = strcmp(v, "auto") == 0 ? "" : v;
       return true;
     }},
    {"fps", [](const char* v, DaemonConfig* c,
               std::string* why) { return ParseWholeNumber(v, 0, 240, &c->fps, why); }},
    {"frame_timeout_ms",
     [](const char* v, DaemonConfig* c, std::string* why) {
       return ParseWholeNumber(v, 100, 60000, &c->frame_timeout_ms, why);
     }},
    {"seed",
     [](const char* v, DaemonConfig* c, std::string* why) {
       int32_t x = 0;
       if (!ParseWholeNumber(v, 0, INT32_MAX, &x, why)) return false;
       c->seed = static_cast<uint64_t>(x);
       return true;
     }},
    {"button",
     [](const char* v, DaemonConfig* c, std::string*) {
       c->button = v;
       return true;
     }},
    {"debounce_ms",
     [](const char* v, DaemonConfig* c, std::string* why) {
       return ParseWholeNumber(v, 0, 500, &c->debounce_ms, why);
     }},
    {"busy_press",
     [](const char* v, DaemonConfig* c, std::string* why) {
       if (strcmp(v, "queue") == 0) {
         c->busy = BusyPolicy::kQueue;
       } else if (strcmp(v, "refuse") == 0) {
         c->busy = BusyPolicy::kRefuse;
       } else {
         return Why(why, "'%s' is neither queue nor refuse", v);
       }
       return true;
     }},
    {"capture_retries",
     [](const char* v, DaemonConfig* c, std::string* why) {
       return ParseWholeNumber(v, 0, 5, &c->capture_retries, why);
     }},
    {"output_dir",
     [](const char* v, DaemonConfig* c, std::string* why) {
       // Room for "/IMG_YYYYMMDD_HHMMSS_NNNN.jpg" and the temporary's suffix within a path.
       if (strlen(v) > 900) return Why(why, "longer than 900 characters");
       c->output_dir = v;
       return true;
     }},
    {"make",
     [](const char* v, DaemonConfig* c, std::string* why) { return Text(v, &c->make, why); }},
    {"model",
     [](const char* v, DaemonConfig* c, std::string* why) { return Text(v, &c->model, why); }},
    {"log_level",
     [](const char* v, DaemonConfig* c, std::string* why) {
       if (ParseLogLevel(v, &c->log_level)) return true;
       return Why(why, "'%s' is none of: debug, info, warning, error", v);
     }},
    {"web", WebAddress},
    {"web_token",
     [](const char* v, DaemonConfig* c, std::string* why) {
       const size_t n = strlen(v);
       if (n < 16 || n > 128) return Why(why, "%zu characters; it needs 16 to 128", n);
       for (const char* p = v; *p != '\0'; ++p) {
         if (*p < '!' || *p > '~') {
           return Why(why, "only printable ASCII characters without spaces are allowed");
         }
       }
       c->web_token = v;
       return true;
     }},
    {"web_root",
     [](const char* v, DaemonConfig* c, std::string* why) {
       if (v[0] != '/') return Why(why, "'%s' is not an absolute path", v);
       if (strlen(v) > 900) return Why(why, "longer than 900 characters");
       c->web_root = v;
       return true;
     }},
};
constexpr int kKeyCount = sizeof(kKeys) / sizeof(kKeys[0]);

// The shared settings' names as refocusd.conf spells them (f_number), after refocusd's own keys.
const std::vector<std::string>& SettingKeys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> out;
    for (int i = 0; const Setting* s = SettingAt(i); ++i) {
      std::string key = s->name;
      for (char& ch : key) ch = ch == '-' ? '_' : ch;
      out.push_back(key);
    }
    return out;
  }();
  return keys;
}

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

const char* ConfigKeyName(int i) {
  if (i >= 0 && i < kKeyCount) return kKeys[i].name;
  const std::vector<std::string>& settings = SettingKeys();
  const size_t j = static_cast<size_t>(i - kKeyCount);
  return i >= kKeyCount && j < settings.size() ? settings[j].c_str() : nullptr;
}

JobOptions DaemonJobDefaults() {
  JobOptions o;
  o.sensor.width = 1280;
  o.sensor.height = 960;
  o.pipeline.labels = 32;  // half the command line's: a board's seconds count
  o.pipeline.geometry = ViewGeometry::kAuto;
  return o;
}

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
  const int count = kKeyCount + static_cast<int>(SettingKeys().size());
  std::vector<int> first_line(static_cast<size_t>(count), 0);
  int line_no = 0;
  int focus_line = 0;
  int web_line = 0;
  // Editors on other systems start a UTF-8 file with a byte-order mark; it is no part of a key.
  const char* p = strncmp(text, "\xEF\xBB\xBF", 3) == 0 ? text + 3 : text;
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
    while (k < count && key != ConfigKeyName(k)) ++k;
    if (k == count) {
      return Status(Code::kInvalidArgument, "%s:%d: unknown key '%.60s'", name, line_no,
                    key.c_str());
    }
    const char* const known = ConfigKeyName(k);
    int& first = first_line[static_cast<size_t>(k)];
    if (first != 0) {
      return Status(Code::kInvalidArgument, "%s:%d: %s is already set on line %d", name, line_no,
                    known, first);
    }
    first = line_no;
    if (value.empty()) {
      return Status(Code::kInvalidArgument, "%s:%d: %s has no value", name, line_no, known);
    }
    std::string why;
    const bool ok = k < kKeyCount
                        ? kKeys[k].parse(value.c_str(), config, &why)
                        : SettingAt(k - kKeyCount)->parse(value.c_str(), &config->job, &why);
    if (!ok) {
      return Status(Code::kInvalidArgument, "%s:%d: %s: %s", name, line_no, known, why.c_str());
    }
    if (strcmp(known, "focus") == 0) focus_line = line_no;
    if (strcmp(known, "web") == 0) web_line = line_no;
    if (strcmp(known, "web_root") == 0) config->web_root_line = line_no;
  }
  config->web_line = web_line;
  // The page shows and changes every photo: never without a token.
  if (config->web_on() && config->web_token.empty()) {
    return Status(Code::kInvalidArgument,
                  "%s:%d: web is on but web_token is not set (16 to 128 characters; the page "
                  "asks for it)",
                  name, web_line);
  }
  // As the command line checks it once the frame size is known (the native size: at start).
  const SensorConfig& sensor = config->job.sensor;
  if (sensor.width > 0) {
    Status s = CheckFocusRegion(config->job.render.focus, sensor.width, sensor.height);
    if (!s.ok()) return s.Prefix("%s:%d: focus: ", name, focus_line);
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
  LB_RETURN_IF_ERROR(ParseConfig(path, text.c_str(), config));
  return CheckWebRoot(path, *config);
}

Status CheckWebRoot(const char* name, const DaemonConfig& config) {
  if (!config.web_on()) return Status::Ok();
  // Without the page every address would answer 404: refused like any other bad value, on the
  // line that chose the folder (the web line when the default is kept).
  const std::string page = config.web_root + "/index.html";
  if (access(page.c_str(), R_OK) == 0) return Status::Ok();
  const int err = errno;
  if (config.web_root_line > 0) {
    return Status(Code::kInvalidArgument, "%s:%d: web_root: cannot read %s: %s", name,
                  config.web_root_line, page.c_str(), strerror(err));
  }
  return Status(Code::kInvalidArgument,
                "%s:%d: web is on but the page's files are missing: cannot read %s: %s (set "
                "web_root)",
                name, config.web_line, page.c_str(), strerror(err));
}

JobOptions MakeJobOptions(const DaemonConfig& config) {
  JobOptions o = config.job;
  o.sensor.timeout_ms = config.frame_timeout_ms;
  o.pipeline.reference = -1;  // the middle frame
  o.make = config.make.c_str();
  o.model = config.model.c_str();
  o.software = "refocusd";
  o.replace = AtomicFile::Replace::kNever;  // a taken name fails the photo, never loses another
  return o;
}

}  // namespace lb
