// refocusd's configuration file: `key = value` lines, `#` comments, blank lines. Every key is
// documented in the default file firmware/daemon/refocusd.conf (installed as /etc/refocusd.conf).
// Unknown keys, keys given twice and bad values are errors naming the file and the line.
#pragma once

#include <cstdint>
#include <string>

#include "algo/core/status.h"
#include "firmware/app/job.h"
#include "firmware/platform/log.h"

namespace lb {

enum class Backend : uint8_t { kV4l2, kLibcamera, kSynthetic };
const char* BackendName(Backend backend);

// What a press does while a photo is being taken.
enum class BusyPolicy : uint8_t { kQueue, kRefuse };

// The photo settings refocusd starts from: the shared table's defaults (firmware/app/settings.h)
// but for fewer depth labels, and auto geometry (a camera is handheld).
JobOptions DaemonJobDefaults();

struct DaemonConfig {
  // Sensor.
  Backend backend = Backend::kV4l2;
  std::string device;  // "" (auto): v4l2 /dev/video0, libcamera the first camera
  int32_t fps = 0;     // v4l2 only; 0 = the driver's choice
  int32_t frame_timeout_ms = 2000;
  uint64_t seed = 1;  // synthetic scene
  // Button.
  std::string button = "auto";  // "auto", an evdev node, or a FIFO of input_event records
  int32_t debounce_ms = 30;
  BusyPolicy busy = BusyPolicy::kQueue;
  int32_t capture_retries = 1;  // fresh bursts after a dropped frame
  // Storage.
  std::string output_dir = "/var/lib/refocusd";
  std::string make = "LensBlur", model = "LensBlur camera";
  // The shared settings: resolution (job.sensor, 0 x 0 = the sensor's native size), frames,
  // depth, lens and JPEG quality.
  JobOptions job = DaemonJobDefaults();
  // Log.
  LogLevel log_level = LogLevel::kInfo;
  // Web page (firmware/web/web_server.h): off while web_address is "". The address is numeric
  // (IPv4 dotted or IPv6 without brackets) and the port 1..65535 (the file refuses 0).
  // web_token is required (16 to 128 printable characters, no space) whenever the web side is
  // on: the page is reachable by anyone on the network.
  std::string web_address;
  int32_t web_port = 0;
  std::string web_token;
  std::string web_root = "/usr/share/refocusd/www";
  bool web_on() const { return !web_address.empty(); }
  // The lines that set web and web_root (0: not in the file), for CheckWebRoot's message.
  int32_t web_line = 0, web_root_line = 0;
};

// Parses the text of a configuration file over the defaults in `config`; `name` is the file
// name for messages ("refocusd.conf:12: unknown key 'burst'").
Status ParseConfig(const char* name, const char* text, DaemonConfig* config);
// Reads and parses `path` (at most 64 KiB), then CheckWebRoot.
Status LoadConfig(const char* path, DaemonConfig* config);
// What ParseConfig cannot see in the text: with web on, web_root must hold a readable
// index.html. The error names `name` and the web_root line (the web line for the default).
Status CheckWebRoot(const char* name, const DaemonConfig& config);

// The job settings the configuration implies; make and model point into `config`.
JobOptions MakeJobOptions(const DaemonConfig& config);

// The keys ParseConfig accepts, i = 0, 1, ... until nullptr: refocusd's own, then the shared
// settings' (tests check each is documented).
const char* ConfigKeyName(int i);

}  // namespace lb
