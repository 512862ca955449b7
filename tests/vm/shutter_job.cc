// The firmware's press-to-file path on real drivers, for the VM scenario shutter_job.sh: waits
// on the evdev button, configures the V4L2 sensor and the job on a half press (or on a press
// that came without one), and turns every press into a JPEG in OUT_DIR. Presses that arrive
// while a job runs wait in the kernel's event queue and are taken afterwards.
//   shutter_job BUTTON_NODE VIDEO_NODE OUT_DIR PRESSES
#include <time.h>

#include <cstdio>
#include <cstdlib>

#include "firmware/app/job.h"
#include "hal/evdev/evdev_button.h"
#include "hal/v4l2/v4l2_sensor.h"

namespace {

double NowS() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: shutter_job BUTTON_NODE VIDEO_NODE OUT_DIR PRESSES\n");
    return 2;
  }
  const int presses = atoi(argv[4]);
  lb::EvdevButton button;
  lb::Status s = button.Open(argv[1]);
  if (!s.ok()) {
    fprintf(stderr, "shutter_job: %s\n", s.message());
    return 1;
  }
  lb::V4l2Options sensor_options;
  sensor_options.device = argv[2];
  sensor_options.fps = 5;
  lb::V4l2Sensor sensor(sensor_options);
  lb::JobOptions options;
  options.sensor.width = 320;
  options.sensor.height = 180;
  options.sensor.frames = 5;
  options.pipeline.max_working_width = 160;
  options.pipeline.max_working_height = 120;
  options.pipeline.labels = 12;
  lb::Job job;
  bool configured = false;
  int saved = 0;
  printf("shutter_job: waiting for the button on %s\n", argv[1]);
  fflush(stdout);
  while (saved < presses) {
    lb::ButtonEvent event;
    s = button.Wait(60000, &event);
    if (!s.ok() || event == lb::ButtonEvent::kNone) {
      fprintf(stderr, "shutter_job: %s\n", s.ok() ? "no press within 60 s" : s.message());
      return 1;
    }
    if (event == lb::ButtonEvent::kRelease) continue;
    if (!configured) {
      double t0 = NowS();
      s = job.Configure(&sensor, options);
      if (!s.ok()) {
        fprintf(stderr, "shutter_job: configure: %s\n", s.message());
        return 1;
      }
      configured = true;
      printf("shutter_job: %s: sensor configured in %.0f ms\n",
             event == lb::ButtonEvent::kHalfPress ? "half press" : "press", (NowS() - t0) * 1e3);
    }
    if (event != lb::ButtonEvent::kPress) continue;
    char path[512];
    snprintf(path, sizeof(path), "%s/shot-%03d.jpg", argv[3], saved + 1);
    lb::JobReport report;
    s = job.Run(path, &report);
    if (!s.ok()) {
      fprintf(stderr, "shutter_job: press %d: %s\n", saved + 1, s.message());
      return 1;
    }
    ++saved;
    printf("shutter_job: press %d: saved %s (capture %.2f s, depth %.2f s, render %.2f s)\n", saved,
           path, report.capture_s, report.depth_s, report.render_s);
    fflush(stdout);
  }
  return 0;
}
