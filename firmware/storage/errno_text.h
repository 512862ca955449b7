// strerror with a lower-case first letter, so it reads as the tail of "path: ...".
#pragma once

#include <cstddef>
#include <cstdio>
#include <cstring>

namespace lb {

inline void ErrnoText(int err, char* out, size_t size) {
  snprintf(out, size, "%s", strerror(err));
  if (out[0] >= 'A' && out[0] <= 'Z' && !(out[1] >= 'A' && out[1] <= 'Z')) out[0] += 'a' - 'A';
}

}  // namespace lb
