// The photo settings `refocus` and refocusd share (lens, burst, depth): one table, so each has
// one name, one range, one meaning and one message wherever it is given. The command line spells
// a name with dashes (--f-number), refocusd.conf with underscores (f_number).
//
// Every number is parsed overflow-safe: "4294967616x240" is an error, never 320x240.
#pragma once

#include <cstdint>
#include <string>

#include "firmware/app/job.h"

namespace lb {

enum class SettingGroup : uint8_t {
  kLens,   // focus, aperture, blur, JPEG quality: run, rerender, refocusd
  kBurst,  // what the sensor is asked for: run (the synthetic scene), refocusd
  kDepth,  // how depth is found: run, refocusd (depth takes a few)
  kWork,   // how the work is spread over the board: run, rerender, refocusd
};

struct Setting {
  const char* name;   // "f-number"
  const char* alias;  // an older command-line spelling still taken ("max-radius"), or nullptr
  SettingGroup group;
  const char* value;  // what the value looks like, for help: "N", "WxH"
  const char* help;   // one line of the command line's help
  // Sets the setting in `job` from `text`; false with `why` ("'0.5' is not a number from 1 to
  // 22") and `job` unchanged.
  bool (*parse)(const char* text, JobOptions* job, std::string* why);
};

// The settings, i = 0, 1, ... until nullptr.
const Setting* SettingAt(int i);
// The setting spelled `name` with dashes or underscores (or its alias), or nullptr.
const Setting* FindSetting(const char* name);

// "--f-number N  aperture as on a lens ..." lines for the settings of `group`.
std::string SettingsHelp(SettingGroup group);

// Sets `why` to the printf-style message (at most 255 characters) and returns false: how every
// value parser, the table's and refocusd.conf's own keys', says what is wrong.
bool Why(std::string* why, const char* format, ...) __attribute__((format(printf, 2, 3)));

// The value parsers the table uses, for options of one command only.
bool ParseWholeNumber(const char* text, int32_t lo, int32_t hi, int32_t* out, std::string* why);
bool ParseRealNumber(const char* text, float lo, float hi, float* out, std::string* why);

}  // namespace lb
