#include "hal/libcamera/exposure_hold.h"

#include <libcamera/control_ids.h>

#include <cstdio>
#include <cstring>

#include "hal/libcamera/libcamera_version.h"

namespace lb {
namespace {

namespace c = libcamera::controls;

bool Lists(const libcamera::ControlInfoMap& available, const libcamera::ControlId& id) {
  return available.count(&id) > 0;
}

// A quantity the burst cannot hold, and why.
struct Missing {
  const char* what;
  const char* why;
};

void WriteNote(const Missing* missing, int n, char* note, size_t size) {
  note[0] = '\0';
  if (n == 0) return;
  size_t used = 0;
  auto append = [&](const char* a, const char* b, const char* c) {
    if (used >= size) return;
    const int r = snprintf(note + used, size - used, "%s%s%s", a, b, c);
    used += r > 0 ? static_cast<size_t>(r) : 0;
  };
  append("cannot hold ", "", "");
  for (int i = 0; i < n; ++i) {
    append(i == 0 ? "" : (i + 1 == n ? " and " : ", "), missing[i].what, " (");
    append(missing[i].why, ")", "");
  }
  append(" across the burst: ", n == 1 ? "it may" : "they may", " drift from frame to frame");
}

const char* WhiteBalanceMissing(const libcamera::ControlInfoMap& available) {
  const bool awb = Lists(available, c::AwbEnable), gains = Lists(available, c::ColourGains);
  if (!awb && !gains) return "no AwbEnable or ColourGains control";
  return !awb ? "no AwbEnable control" : "no ColourGains control";
}

}  // namespace

bool CanHoldAny(const libcamera::ControlInfoMap& available) {
  return Lists(available, c::ExposureTime) || Lists(available, c::AnalogueGain) ||
         (Lists(available, c::AwbEnable) && Lists(available, c::ColourGains));
}

HeldControls HoldExposure(const libcamera::ControlInfoMap& available,
                          const libcamera::ControlList& metered, libcamera::ControlList* out) {
  HeldControls held;
  Missing missing[3];
  int n = 0;

  const auto exposure = metered.get(c::ExposureTime);
  if (!Lists(available, c::ExposureTime)) {
    missing[n++] = {"exposure", "no ExposureTime control"};
  } else if (!exposure) {
    missing[n++] = {"exposure", "the metered frame reports no ExposureTime"};
  } else {
    held.exposure = true;
  }
  const auto gain = metered.get(c::AnalogueGain);
  if (!Lists(available, c::AnalogueGain)) {
    missing[n++] = {"gain", "no AnalogueGain control"};
  } else if (!gain) {
    missing[n++] = {"gain", "the metered frame reports no AnalogueGain"};
  } else {
    held.gain = true;
  }
  const auto colour_gains = metered.get(c::ColourGains);
  if (!Lists(available, c::AwbEnable) || !Lists(available, c::ColourGains)) {
    missing[n++] = {"white balance", WhiteBalanceMissing(available)};
  } else if (!colour_gains) {
    missing[n++] = {"white balance", "the metered frame reports no ColourGains"};
  } else {
    held.white_balance = true;
  }

  // The automatic exposure stops only where a value replaces it: with neither, the camera keeps
  // running it rather than freezing on values nobody read.
  if (held.exposure || held.gain) {
#if LB_LIBCAMERA_AT_LEAST(0, 5, 0)
    if (held.exposure && Lists(available, c::ExposureTimeMode)) {
      out->set(c::ExposureTimeMode, static_cast<int32_t>(c::ExposureTimeModeManual));
    }
    if (held.gain && Lists(available, c::AnalogueGainMode)) {
      out->set(c::AnalogueGainMode, static_cast<int32_t>(c::AnalogueGainModeManual));
    }
#endif
    if (Lists(available, c::AeEnable)) out->set(c::AeEnable, false);
  }
  if (held.exposure) out->set(c::ExposureTime, *exposure);
  if (held.gain) out->set(c::AnalogueGain, *gain);
  if (held.white_balance) {
    out->set(c::AwbEnable, false);
    out->set(c::ColourGains, *colour_gains);
  }
  WriteNote(missing, n, held.note, sizeof(held.note));
  return held;
}

void HoldReporter::Note(const char* camera_id, const HeldControls& held) {
  if (strcmp(held.note, last_) == 0) return;
  snprintf(last_, sizeof(last_), "%s", held.note);
  if (held.note[0] == '\0' || report_ == nullptr) return;
  char line[sizeof(held.note) + 160];
  snprintf(line, sizeof(line), "libcamera %s: %s", camera_id, held.note);
  report_(context_, line);
}

}  // namespace lb
