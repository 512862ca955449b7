// Integer min / max / clamp / abs for algo: one definition, int32 overloads (no template, so a
// mixed call does not silently pick a wider type). Exact; no rounding.
#pragma once

#include <cstdint>

namespace lb {

constexpr int32_t Min(int32_t a, int32_t b) { return a < b ? a : b; }
constexpr int32_t Max(int32_t a, int32_t b) { return a > b ? a : b; }
// lo <= hi; v below lo gives lo, above hi gives hi.
constexpr int32_t Clamp(int32_t v, int32_t lo, int32_t hi) {
  return v < lo ? lo : (v > hi ? hi : v);
}
// |v| for v > INT32_MIN.
constexpr int32_t Abs(int32_t v) { return v < 0 ? -v : v; }

}  // namespace lb
