#include "hal/libcamera/exposure_hold.h"

#include <libcamera/control_ids.h>

namespace lb {

HeldControls HoldExposure(const libcamera::ControlInfoMap& available,
                          const libcamera::ControlList& metered, libcamera::ControlList* out) {
  namespace c = libcamera::controls;
  HeldControls held;
  auto has = [&](const libcamera::ControlId& id) { return available.count(&id) > 0; };

  auto exposure = metered.get(c::ExposureTime);
  auto gain = metered.get(c::AnalogueGain);
  if (has(c::AeEnable) && has(c::ExposureTime) && has(c::AnalogueGain) && exposure && gain) {
    out->set(c::AeEnable, false);
    out->set(c::ExposureTime, *exposure);
    out->set(c::AnalogueGain, *gain);
    held.exposure = true;
  }
  auto gains = metered.get(c::ColourGains);
  if (has(c::AwbEnable) && has(c::ColourGains) && gains) {
    out->set(c::AwbEnable, false);
    out->set(c::ColourGains, *gains);
    held.white_balance = true;
  }
  return held;
}

}  // namespace lb
