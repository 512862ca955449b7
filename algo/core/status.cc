#include "algo/core/status.h"

#include <cstdio>
#include <cstring>

namespace lb {

// clang-analyzer's valist checker loses the va_start of these two functions when it analyses
// this file after others in one run (clang-tidy 14), and calls the list uninitialised.
Status::Status(Code code, const char* format, ...) : code_(code) {
  va_list args;
  va_start(args, format);
  vsnprintf(message_, sizeof(message_), format, args);  // NOLINT(clang-analyzer-valist.*)
  va_end(args);
}

Status& Status::Prefix(const char* format, ...) {
  char prefix[kMaxMessage];
  va_list args;
  va_start(args, format);
  int n = vsnprintf(prefix, sizeof(prefix), format, args);  // NOLINT(clang-analyzer-valist.*)
  va_end(args);
  if (n <= 0) return *this;
  // Shift the old message right to make room, then put the prefix in front (truncating the end).
  const size_t plen =
      static_cast<size_t>(n) < kMaxMessage - 1 ? static_cast<size_t>(n) : kMaxMessage - 1;
  const size_t mlen = strnlen(message_, kMaxMessage - 1);
  const size_t keep = mlen < kMaxMessage - 1 - plen ? mlen : kMaxMessage - 1 - plen;
  memmove(message_ + plen, message_, keep);
  memcpy(message_, prefix, plen);
  message_[plen + keep] = '\0';
  return *this;
}

}  // namespace lb
