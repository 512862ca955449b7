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
// The same with the settings named, for a command that takes only a few of a group.
std::vector<option> WithSettings(std::initializer_list<option> own,
                                 std::initializer_list<const char*> names);
// The setting behind option `id`, or nullptr for a command's own option.
const Setting* SettingOfOption(int id);

// What OptionReader::Next returns for an argument that is no option, when `letters` asks for
// arguments in place.
inline constexpr int kPositional = 1;

// getopt_long over one command's arguments (argv[0] is the command's name): its own options come
// back one at a time, the settings are parsed on the way, and every usage problem is one line.
class OptionReader {
 public:
  // `options` from WithSettings; `letters` is getopt's optstring: ":" for long options only, a
  // leading "-" keeps the other arguments in place (refocus depth: the files after --views).
  OptionReader(int argc, char** argv, std::vector<option> options, const char* letters = ":");

  // The next option's id, a setting's once parsed into `job`; kPositional; or -1 after the last
  // (rest() then indexes what is left). 0 with error() set when a value is missing, an option
  // unknown, a setting's value wrong or a setting given twice (under either of its names).
  int Next(JobOptions* job);
  const char* arg() const { return arg_; }
  // The option's long name as the user chose it, without the dashes: an alias stays an alias
  // ("size", not "resolution").
  const char* name() const { return name_; }
  const std::string& error() const { return error_; }
  int rest() const { return optind; }

  // Takes arg() into `value` for an option given at most once; false with `error` otherwise.
  bool Once(std::string* value, std::string* error) const;

 private:
  int Problem(std::string message);

  int argc_;
  char** argv_;
  std::vector<option> options_;
  const char* letters_;
  const char* arg_ = nullptr;
  const char* name_ = nullptr;
  std::string error_;
  std::vector<const char*> given_;  // by setting index: the name it was first given under
};

// Prints "refocus: <message>" on stderr and returns exit code 1.
int Fail(const char* message);
// Prints "refocus COMMAND: <problem> ('refocus COMMAND --help' lists the options)" on stderr
// and returns exit code 2.
int UsageError(const char* command, const std::string& problem);

}  // namespace lb::cli
