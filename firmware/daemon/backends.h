// The sensor and the shutter button a configuration names, built from the hal/ backends.
#pragma once

#include <memory>
#include <string>

#include "algo/core/status.h"
#include "firmware/daemon/config.h"
#include "firmware/platform/log.h"
#include "hal/button.h"
#include "hal/sensor.h"

namespace lb {

// The backends this build holds, e.g. "v4l2, libcamera, synthetic".
const char* BuiltBackends();

// `log` (may be null) gets the sensor's warnings: what the libcamera sensor cannot hold constant
// across a burst, the corrupt MJPEG frames the V4L2 sensor skipped.
Status MakeSensor(const DaemonConfig& config, std::unique_ptr<Sensor>* sensor, Log* log = nullptr);

// `button`: "auto" (the first input device that sends KEY_CAMERA), an evdev node, or a FIFO
// that carries struct input_event records (how the host tests press the button). `*where` gets
// the path opened.
Status OpenButton(const DaemonConfig& config, std::unique_ptr<Button>* button, std::string* where);

}  // namespace lb
