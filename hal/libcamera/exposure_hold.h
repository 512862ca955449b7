// Exposure and white balance held constant across a burst: the views must differ only by
// viewpoint for the depth stage to match them. The sensor meters one frame with the camera's
// automatic algorithms, then every burst request carries that frame's exposure time, gain and
// colour gains with the algorithms off. Only controls the camera exposes are set.
#pragma once

#include <libcamera/controls.h>

namespace lb {

struct HeldControls {
  bool exposure = false;       // AeEnable off, ExposureTime and AnalogueGain fixed
  bool white_balance = false;  // AwbEnable off, ColourGains fixed
};

// Writes into `out` the controls that fix what `metered` (a completed request's metadata)
// reports, limited to what `available` (Camera::controls()) holds.
HeldControls HoldExposure(const libcamera::ControlInfoMap& available,
                          const libcamera::ControlList& metered, libcamera::ControlList* out);

}  // namespace lb
