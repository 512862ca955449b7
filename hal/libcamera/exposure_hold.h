// Exposure, gain and white balance held constant across a burst: the views must differ only by
// viewpoint for the depth stage to match them. The sensor meters one frame with the camera's
// automatic algorithms, then every burst request carries that frame's exposure time, gain and
// colour gains with the algorithms off, all in one ControlList. Only controls the camera lists
// are set, and what cannot be held is said in a line the sensor's owner logs.
//
// How the algorithms are stopped depends on the libcamera version. Up to 0.4, AeEnable = false
// stops exposure and gain together. From 0.5, ExposureTime and AnalogueGain act only when
// ExposureTimeMode and AnalogueGainMode are Manual, and AeEnable is an input the Camera turns
// into both modes, which a pipeline need not list: each is set wherever it is listed. White
// balance is AwbEnable = false with ColourGains on every version.
#pragma once

#include <libcamera/controls.h>

namespace lb {

struct HeldControls {
  bool exposure = false;       // ExposureTime fixed, its automatic control off
  bool gain = false;           // AnalogueGain fixed, its automatic control off
  bool white_balance = false;  // AwbEnable off, ColourGains fixed
  // Empty when all three are held; otherwise which are not and why, e.g. "cannot hold white
  // balance (no AwbEnable control) across the burst: it may drift from frame to frame".
  char note[320] = {};
};

// Whether `available` (Camera::controls()) lists any control HoldExposure sets: when not, no
// frame need be metered.
bool CanHoldAny(const libcamera::ControlInfoMap& available);

// Writes into `out` the controls that fix what `metered` (a completed request's metadata)
// reports, limited to what `available` lists.
HeldControls HoldExposure(const libcamera::ControlInfoMap& available,
                          const libcamera::ControlList& metered, libcamera::ControlList* out);

// Passes a camera's HeldControls note to the sensor's owner as one line, "libcamera ID: NOTE":
// once, and again only when it changes, so a daemon taking photo after photo says it once.
class HoldReporter {
 public:
  using Report = void (*)(void* context, const char* line);

  HoldReporter(Report report, void* context) : report_(report), context_(context) {}
  // Forgets the last line (a new configuration may be another camera).
  void Reset() { last_[0] = '\0'; }
  void Note(const char* camera_id, const HeldControls& held);

 private:
  Report report_;
  void* context_;
  char last_[sizeof(HeldControls::note)] = {};
};

}  // namespace lb
