#include "firmware/cli/options.h"

#include <cstdio>
#include <cstring>
#include <utility>

namespace lb::cli {

bool ParseDisparityRange(const char* text, int32_t* lo_q8, int32_t* hi_q8, std::string* error) {
  float lo = 0, hi = 0;
  char tail = 0;
  if (sscanf(text, "%f,%f%c", &lo, &hi, &tail) != 2 || !(lo >= -255) || !(hi > lo) ||
      !(hi <= 255) || hi - lo > 255) {
    *error = std::string("disparity '") + text +
             "' is not MIN,MAX with -255 <= MIN < MAX <= 255, at most 255 apart";
    return false;
  }
  *lo_q8 = static_cast<int32_t>(__builtin_floor(lo * 256.0f + 0.5f));
  *hi_q8 = static_cast<int32_t>(__builtin_floor(hi * 256.0f + 0.5f));
  return true;
}

namespace {

// `own`, the settings `wanted(setting)` picks under their names and aliases, the zero entry.
template <typename Wanted>
std::vector<option> Collect(std::initializer_list<option> own, Wanted wanted) {
  std::vector<option> all(own);
  for (int i = 0; const Setting* s = SettingAt(i); ++i) {
    if (!wanted(*s)) continue;
    all.push_back({s->name, required_argument, nullptr, kFirstSettingOption + i});
    if (s->alias) all.push_back({s->alias, required_argument, nullptr, kFirstSettingOption + i});
  }
  all.push_back({nullptr, 0, nullptr, 0});
  return all;
}

}  // namespace

std::vector<option> WithSettings(std::initializer_list<option> own,
                                 std::initializer_list<SettingGroup> groups) {
  return Collect(own, [groups](const Setting& s) {
    for (SettingGroup g : groups) {
      if (s.group == g) return true;
    }
    return false;
  });
}

std::vector<option> WithSettings(std::initializer_list<option> own,
                                 std::initializer_list<const char*> names) {
  return Collect(own, [names](const Setting& s) {
    for (const char* name : names) {
      if (strcmp(s.name, name) == 0) return true;
    }
    return false;
  });
}

const Setting* SettingOfOption(int id) {
  return id >= kFirstSettingOption ? SettingAt(id - kFirstSettingOption) : nullptr;
}

OptionReader::OptionReader(int argc, char** argv, std::vector<option> options, const char* letters)
    : argc_(argc), argv_(argv), options_(std::move(options)), letters_(letters) {
  optind = 0;  // not 1: glibc reads a new optstring's "-" only when it starts over
  opterr = 0;  // Next says it in one line
}

int OptionReader::Next(JobOptions* job) {
  int index = -1;
  const int c = getopt_long(argc_, argv_, letters_, options_.data(), &index);
  arg_ = optarg;
  name_ = index >= 0 ? options_[static_cast<size_t>(index)].name : nullptr;
  if (c == ':') return Problem(std::string(argv_[optind - 1]) + " needs a value");
  if (c == '?') return Problem(std::string("unknown option '") + argv_[optind - 1] + "'");
  if (const Setting* s = SettingOfOption(c)) {
    // refocusd.conf refuses a key given twice; the command line keeps the same rule rather
    // than let the last one win unnoticed.
    const size_t i = static_cast<size_t>(c - kFirstSettingOption);
    if (given_.size() <= i) given_.resize(i + 1, nullptr);
    if (given_[i] != nullptr) {
      return Problem(strcmp(given_[i], name_) == 0
                         ? std::string("--") + name_ + " given twice"
                         : std::string("--") + name_ + " given twice (--" + given_[i] +
                               " is the same setting)");
    }
    given_[i] = name_;
    std::string why;
    if (!s->parse(arg_, job, &why)) return Problem(std::string("--") + name_ + ": " + why);
  }
  return c;
}

bool OptionReader::Once(std::string* value, std::string* error) const {
  if (!value->empty()) {
    *error = std::string("--") + name_ + " given twice";
    return false;
  }
  *value = arg_;
  return true;
}

int OptionReader::Problem(std::string message) {
  error_ = std::move(message);
  return 0;
}

int Fail(const char* message) {
  fprintf(stderr, "refocus: %s\n", message);
  return 1;
}

int UsageError(const char* command, const std::string& problem) {
  fprintf(stderr, "refocus %s: %s ('refocus %s --help' lists the options)\n", command,
          problem.c_str(), command);
  return 2;
}

}  // namespace lb::cli
