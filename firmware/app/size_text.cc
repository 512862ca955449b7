#include "firmware/app/size_text.h"

#include <cerrno>
#include <cstdlib>

namespace lb {
namespace {

// One number of 1-9 decimal digits (no sign, no spaces) within [lo, hi]; `text` moves past it.
bool Number(const char** text, int32_t lo, int32_t hi, int32_t* out) {
  const char* p = *text;
  if (*p < '0' || *p > '9') return false;
  char* end = nullptr;
  errno = 0;
  const long long v = strtoll(p, &end, 10);
  if (errno != 0 || end - p > 9 || v < lo || v > hi) return false;
  *out = static_cast<int32_t>(v);
  *text = end;
  return true;
}

}  // namespace

bool ParseSizeText(const char* text, int32_t lo, int32_t hi, int32_t* width, int32_t* height) {
  const char* p = text;
  int32_t w = 0, h = 0;
  if (!Number(&p, lo, hi, &w) || *p++ != 'x' || !Number(&p, lo, hi, &h) || *p != '\0') {
    return false;
  }
  *width = w;
  *height = h;
  return true;
}

}  // namespace lb
