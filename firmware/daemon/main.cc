// refocusd: the camera's lens-blur daemon. Waits for the shutter button, takes a burst, computes
// depth, renders the shallow depth of field and saves the JPEG; see camera_daemon.h.
#include <getopt.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "firmware/daemon/backends.h"
#include "firmware/daemon/camera_daemon.h"
#include "firmware/daemon/clock.h"
#include "firmware/daemon/config.h"
#include "firmware/daemon/startup_checks.h"
#include "firmware/daemon/web_page.h"
#include "firmware/platform/cpu_features.h"
#include "firmware/platform/log.h"
#include "firmware/web/web_server.h"

namespace {

const char kUsage[] =
    "usage: refocusd [--config FILE] [--check-config]\n"
    "\n"
    "The lens-blur camera daemon: each press of the shutter button (KEY_CAMERA) takes a burst,\n"
    "computes depth, renders a shallow depth of field and saves IMG_YYYYMMDD_HHMMSS_NNNN.jpg in\n"
    "the output folder. A half press (KEY_CAMERA_FOCUS) readies the sensor. Logs go to stderr\n"
    "(the journal under systemd); SIGTERM, SIGINT or SIGHUP stop it after the photo in\n"
    "progress.\n"
    "\n"
    "At start it checks the camera (there, and a capture device) and the output folder (there,\n"
    "and writable) and says \"ready\" once both hold. Until then it logs each problem once,\n"
    "checks again after 1 s, 2 s, 4 s ... and then every 30 s (a camera plugged in or a card\n"
    "mounted later is found), and refuses a press with the reason unless a check at that press\n"
    "passes. A button that cannot be opened stops it (exit 1).\n"
    "\n"
    "With web = ADDRESS:PORT it also serves the photo page (a gallery, tap to refocus, save,\n"
    "download; web_token required); a port it cannot bind is logged and the camera runs on.\n"
    "\n"
    "  --config FILE     configuration (default /etc/refocusd.conf; every key is documented "
    "there)\n"
    "  --check-config    read the configuration and check the camera, the button and the output\n"
    "                    folder as at start (and the web page's files when web is on); print\n"
    "                    every problem, one per line, and exit 1, or\n"
    "                    \"configuration OK\" and exit 0 when everything holds\n"
    "  --version         print the version and the sensor backends of this build\n"
    "  --help            this text\n"
    "\n"
    "Exit status: 0 stopped by a signal (--check-config: all holds), 1 a configuration or button\n"
    "failure (--check-config: any problem), 2 usage.\n";

std::atomic<lb::CameraDaemon*> g_daemon{nullptr};

void OnStopSignal(int) {
  lb::CameraDaemon* d = g_daemon.load();
  if (d != nullptr) d->RequestStop();
}

int Usage(const char* error) {
  fprintf(stderr, "refocusd: %s\n\n%s", error, kUsage);
  return 2;
}

// --check-config once the file reads: the checks refocusd runs at start (camera, output folder)
// and the button it would open, each problem on its own line, so "configuration OK" means
// refocusd would start and say "ready" now. The first line names the sensor backends this build
// has, since `backend =` can only name one of them.
int CheckConfig(const char* path, const lb::DaemonConfig& config) {
  printf("refocusd: sensor backends: %s\n", lb::BuiltBackends());
  fflush(stdout);
  int problems = 0;
  std::unique_ptr<lb::Sensor> sensor;
  lb::Status s = lb::MakeSensor(config, &sensor);
  if (s.ok()) s = sensor->Probe();
  if (!s.ok()) {
    fprintf(stderr, "refocusd: %s\n", s.message());
    ++problems;
  }
  std::unique_ptr<lb::Button> button;
  std::string button_path;
  s = lb::OpenButton(config, &button, &button_path);
  if (!s.ok()) {
    fprintf(stderr, "refocusd: button: %s\n", s.message());
    ++problems;
  }
  s = lb::CheckPhotoFolder(config.output_dir.c_str());
  if (!s.ok()) {
    fprintf(stderr, "refocusd: %s\n", s.message());
    ++problems;
  }
  if (problems > 0) return 1;
  printf("refocusd: %s: configuration OK\n", path);
  return 0;
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
  lb::UseThisCpu();  // the row kernels this processor runs (NEON on a 32-bit ARM that has it)

  lb::DaemonConfig config;
  lb::Status s = lb::LoadConfig(config_path.c_str(), &config);
  if (!s.ok()) {
    fprintf(stderr, "refocusd: %s\n", s.message());
    return 1;
  }
  if (check_only) return CheckConfig(config_path.c_str(), config);

  lb::FdLogSink sink(2, lb::FdLogSink::IsJournal(2));
  lb::Log log(&sink, config.log_level);
  log.Printf(lb::LogLevel::kInfo, "refocusd %s starting (configuration %s)", LB_VERSION,
             config_path.c_str());

  std::unique_ptr<lb::Sensor> sensor;
  std::unique_ptr<lb::Button> button;
  std::string button_path;
  s = lb::MakeSensor(config, &sensor, &log);
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
  // A closed terminal or a stray `kill -HUP` must not cut a photo short: taken as SIGTERM.
  sigaction(SIGHUP, &sa, nullptr);
  // A closed log pipe must not kill the camera; writes then fail quietly.
  signal(SIGPIPE, SIG_IGN);

  s = daemon.Start();
  // The web page (web = ADDRESS:PORT) after the camera: a port that cannot be bound is logged
  // and the camera runs on without it. Declared after the daemon, so it goes first.
  std::unique_ptr<lb::RefocusBackend> backend;
  std::unique_ptr<lb::WebServer> web;
  if (s.ok() && config.web_on()) {
    backend = lb::MakeRefocusBackend(config, &log, daemon);
    web = std::make_unique<lb::WebServer>(lb::WebOptionsFrom(config), backend.get(), &log);
    lb::Status ws = web->Start();
    if (!ws.ok()) {
      log.Printf(lb::LogLevel::kError, "%s; the camera runs without the web page", ws.message());
      web.reset();
      // The renderer is sized for the largest photo and has its own threads: a page that will
      // not come must not keep them.
      backend.reset();
    }
  }
  if (s.ok()) s = daemon.Run();
  if (web) web->Stop();
  g_daemon.store(nullptr);
  return s.ok() ? 0 : 1;
}
