#include "firmware/cli/options.h"

#include <cstdio>

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

std::vector<option> WithSettings(std::initializer_list<option> own,
                                 std::initializer_list<SettingGroup> groups) {
  std::vector<option> all(own);
  for (int i = 0; const Setting* s = SettingAt(i); ++i) {
    bool wanted = false;
    for (SettingGroup g : groups) wanted |= s->group == g;
    if (!wanted) continue;
    all.push_back({s->name, required_argument, nullptr, kFirstSettingOption + i});
    if (s->alias) all.push_back({s->alias, required_argument, nullptr, kFirstSettingOption + i});
  }
  all.push_back({nullptr, 0, nullptr, 0});
  return all;
}

const Setting* SettingOfOption(int id) {
  return id >= kFirstSettingOption ? SettingAt(id - kFirstSettingOption) : nullptr;
}

namespace {

bool Parse(const Setting* s, const char* arg, JobOptions* job, std::string* error) {
  std::string why;
  if (s->parse(arg, job, &why)) return true;
  *error = std::string("--") + s->name + ": " + why;
  return false;
}

}  // namespace

bool ParseSettingOption(int id, const char* arg, JobOptions* job, std::string* error) {
  const Setting* s = SettingOfOption(id);
  if (s == nullptr) {
    *error = "unknown option";
    return false;
  }
  return Parse(s, arg, job, error);
}

bool ParseSettingNamed(const char* name, const char* arg, JobOptions* job, std::string* error) {
  const Setting* s = FindSetting(name);
  if (s == nullptr) {
    *error = std::string("unknown option '--") + name + "'";
    return false;
  }
  return Parse(s, arg, job, error);
}

int Fail(const char* message) {
  fprintf(stderr, "refocus: %s\n", message);
  return 1;
}

}  // namespace lb::cli
