// The command-line options the subcommands share. Each parser returns false and fills a one-line
// message when the text is not a valid value.
#pragma once

#include <getopt.h>

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/app/settings.h"

namespace lb::cli {

// "MIN,MAX" in px per view step, signed (a converged rig has both signs): -255 <= MIN < MAX
// <= 255, at most 255 apart; Q8.8 out, rounded to nearest.
bool ParseDisparityRange(const char* text, int32_t* lo_q8, int32_t* hi_q8, std::string* error);

// The shared settings as options (firmware/app/settings.h): ids from kFirstSettingOption up are
// the settings' indices; a command's own ids stay below.
inline constexpr int kFirstSettingOption = 1000;
// `own` (without the terminating zero entry), then every setting of `groups` under its name and
// its alias, then the zero entry.
std::vector<option> WithSettings(std::initializer_list<option> own,
                                 std::initializer_list<SettingGroup> groups);
// The setting behind option `id`, or nullptr for a command's own option.
const Setting* SettingOfOption(int id);
// Parses setting option `id` into `job`; false with `error` naming the option.
bool ParseSettingOption(int id, const char* arg, JobOptions* job, std::string* error);
// The same by the setting's name, for commands that walk argv themselves.
bool ParseSettingNamed(const char* name, const char* arg, JobOptions* job, std::string* error);

// Prints "refocus: <message>" on stderr and returns exit code 1.
int Fail(const char* message);

}  // namespace lb::cli
