#include "firmware/daemon/backends.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "hal/evdev/evdev_button.h"
#include "hal/v4l2/v4l2_sensor.h"
#include "sim/synthetic/synthetic_sensor.h"
#ifdef LB_HAVE_LIBCAMERA
#include "hal/libcamera/libcamera_sensor.h"
#endif

namespace lb {

static void LogSensorLine(void* log, const char* line) {
  static_cast<Log*>(log)->Printf(LogLevel::kWarning, "%s", line);
}

const char* BuiltBackends() {
#ifdef LB_HAVE_LIBCAMERA
  return "v4l2, libcamera, synthetic";
#else
  return "v4l2, synthetic";
#endif
}

Status MakeSensor(const DaemonConfig& config, std::unique_ptr<Sensor>* sensor, Log* log) {
  switch (config.backend) {
    case Backend::kV4l2: {
      V4l2Options o;
      if (!config.device.empty()) o.device = config.device.c_str();  // copied by the sensor
      o.fps = config.fps;
      if (log != nullptr) {
        o.log = LogSensorLine;
        o.log_context = log;
      }
      *sensor = std::make_unique<V4l2Sensor>(o);
      return Status::Ok();
    }
    case Backend::kLibcamera: {
#ifdef LB_HAVE_LIBCAMERA
      LibcameraOptions o;
      o.camera_id = config.device.c_str();
      if (log != nullptr) {
        o.log = LogSensorLine;
        o.log_context = log;
      }
      *sensor = std::make_unique<LibcameraSensor>(o);
      return Status::Ok();
#else
      return Status(Code::kUnsupported,
                    "backend libcamera: this build has no libcamera support (built: %s)",
                    BuiltBackends());
#endif
    }
    case Backend::kSynthetic: {
      SceneParams params;
      params.seed = config.seed;
      *sensor = std::make_unique<SyntheticSensor>(params);
      return Status::Ok();
    }
  }
  return Status(Code::kInternal, "unknown backend");
}

Status OpenButton(const DaemonConfig& config, std::unique_ptr<Button>* button, std::string* where) {
  auto evdev = std::make_unique<EvdevButton>(config.debounce_ms);
  char path[256];
  if (config.button == "auto") {
    LB_RETURN_IF_ERROR(EvdevButton::FindCameraButton(path, sizeof(path)));
  } else {
    snprintf(path, sizeof(path), "%s", config.button.c_str());
  }
  struct stat st;
  if (stat(path, &st) == 0 && S_ISFIFO(st.st_mode)) {
    // Read-write, so the FIFO never reports end of file when a writer goes away.
    const int fd = open(path, O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return Status(Code::kIoError, "%s: cannot open: %s", path, strerror(errno));
    evdev->Adopt(fd, path);
  } else {
    LB_RETURN_IF_ERROR(evdev->Open(path));
  }
  *where = path;
  *button = std::move(evdev);
  return Status::Ok();
}

}  // namespace lb
