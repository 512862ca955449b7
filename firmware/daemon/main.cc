// refocusd: the camera's lens-blur daemon. Waits for the shutter button, takes a burst, computes
// depth, renders the shallow depth of field and saves the JPEG; see camera_daemon.h.
#include <getopt.h>
#include <signal.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "firmware/daemon/backends.h"
#include "firmware/daemon/camera_daemon.h"
#include "firmware/daemon/clock.h"
#include "firmware/daemon/config.h"
#include "firmware/daemon/log.h"

namespace {

const char kUsage[] =
    "usage: refocusd [--config FILE] [--check-config]\n"
    "\n"
    "The lens-blur camera daemon: each press of the shutter button (KEY_CAMERA) takes a burst,\n"
    "computes depth, renders a shallow depth of field and saves IMG_YYYYMMDD_HHMMSS_NNNN.jpg in\n"
    "the output folder. A half press (KEY_CAMERA_FOCUS) readies the sensor. Logs go to stderr\n"
    "(the journal under systemd); SIGTERM or SIGINT stop it after the photo in progress.\n"
    "\n"
    "  --config FILE     configuration (default /etc/refocusd.conf; every key is documented "
    "there)\n"
    "  --check-config    read the configuration, report the first problem, and exit\n"
    "  --version         print the version and the sensor backends of this build\n"
    "  --help            this text\n"
    "\n"
    "Exit status: 0 stopped by a signal, 1 a configuration, device or button failure, 2 usage.\n";

std::atomic<lb::CameraDaemon*> g_daemon{nullptr};

void OnStopSignal(int) {
  lb::CameraDaemon* d = g_daemon.load();
  if (d != nullptr) d->RequestStop();
}

int Usage(const char* error) {
  fprintf(stderr, "refocusd: %s\n\n%s", error, kUsage);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  const option options[] = {
      {"config", required_argument, nullptr, 'c'},
      {"check-config", no_argument, nullptr, 'k'},
      {"version", no_argument, nullptr, 'v'},
      {"help", no_argument, nullptr, 'h'},
      {nullptr, 0, nullptr, 0},
  };
  std::string config_path = "/etc/refocusd.conf";
  bool check_only = false;
  opterr = 0;
  for (int c; (c = getopt_long(argc, argv, "", options, nullptr)) != -1;) {
    switch (c) {
      case 'c':
        config_path = optarg;
        break;
      case 'k':
        check_only = true;
        break;
      case 'v':
        printf("refocusd %s (sensor backends: %s)\n", LB_VERSION, lb::BuiltBackends());
        return 0;
      case 'h':
        fputs(kUsage, stdout);
        return 0;
      default:
        return Usage("unknown option, or an option without its value");
    }
  }
  if (optind < argc) return Usage("unexpected argument");

  lb::DaemonConfig config;
  lb::Status s = lb::LoadConfig(config_path.c_str(), &config);
  if (!s.ok()) {
    fprintf(stderr, "refocusd: %s\n", s.message());
    return 1;
  }
  if (check_only) {
    printf("refocusd: %s: configuration OK\n", config_path.c_str());
    return 0;
  }

  lb::FdLogSink sink(2, lb::FdLogSink::IsJournal(2));
  lb::Log log(&sink, config.log_level);
  log.Printf(lb::LogLevel::kInfo, "refocusd %s starting (configuration %s)", LB_VERSION,
             config_path.c_str());

  std::unique_ptr<lb::Sensor> sensor;
  std::unique_ptr<lb::Button> button;
  std::string button_path;
  s = lb::MakeSensor(config, &sensor);
  if (s.ok()) s = lb::OpenButton(config, &button, &button_path);
  if (!s.ok()) {
    log.Printf(lb::LogLevel::kError, "%s", s.message());
    return 1;
  }
  log.Printf(lb::LogLevel::kInfo, "button: %s", button_path.c_str());

  lb::SystemClock clock;
  lb::CameraDaemon daemon(config, sensor.get(), button.get(), &clock, &log);
  g_daemon.store(&daemon);
  struct sigaction sa;
  memset(&sa, 0, sizeof(sa));
  sa.sa_handler = OnStopSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);
  // A closed log pipe must not kill the camera; writes then fail quietly.
  signal(SIGPIPE, SIG_IGN);

  s = daemon.Start();
  if (s.ok()) s = daemon.Run();
  g_daemon.store(nullptr);
  return s.ok() ? 0 : 1;
}
