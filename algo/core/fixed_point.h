// Fixed-point helpers. Qm.n has n fractional bits, and a name ends with its format's fractional
// bits: variables and members `_qN` (`disp_q8`, `x_q16`, `recip_q15_`), functions and constants
// `QN` (`LabelDispQ8`, `RecipQ15`, `kHalfQ16`). Every helper states its rounding.
#pragma once

#include <cstdint>
#include <limits>
#include <type_traits>

namespace lb::fx {

// Fractional bits of the formats used across the pipeline.
inline constexpr int kQ8 = 8;    // disparity in px per view step: uint16 Q8.8, up to 255.996 px
inline constexpr int kQ12 = 12;  // interpolation weights: 0..4096
inline constexpr int kQ15 = 15;  // normalised weights and colour-matrix coefficients
inline constexpr int kQ16 = 16;  // 16.16 general-purpose coordinates

template <int Frac>
constexpr int32_t One() {
  return int32_t{1} << Frac;
}

// Converts a real constant to fixed point, rounding half away from zero. For constants and
// configure-time values only: never on the per-pixel path.
template <int Frac>
constexpr int32_t FromDouble(double v) {
  const double scaled = v * static_cast<double>(int64_t{1} << Frac);
  return static_cast<int32_t>(scaled >= 0 ? scaled + 0.5 : scaled - 0.5);
}

// Arithmetic shift right with round-half-up (adds 2^(s-1) first). s must be >= 1.
template <typename T>
constexpr T RoundShift(T v, int s) {
  return static_cast<T>((v + (T{1} << (s - 1))) >> s);
}

// Clamps an int64 into the range of T.
template <typename T>
constexpr T Saturate(int64_t v) {
  static_assert(std::is_integral_v<T>);
  constexpr int64_t lo = static_cast<int64_t>(std::numeric_limits<T>::min());
  constexpr int64_t hi = static_cast<int64_t>(std::numeric_limits<T>::max());
  return static_cast<T>(v < lo ? lo : (v > hi ? hi : v));
}

constexpr uint8_t ClampU8(int32_t v) {
  return static_cast<uint8_t>(v < 0 ? 0 : (v > 255 ? 255 : v));
}

// Saturating add for int32 energies (a + b, clamped to the int32 range).
constexpr int32_t AddSat(int32_t a, int32_t b) { return Saturate<int32_t>(int64_t{a} + b); }

// Q.a x Q.b -> Q.(a+b-s), rounded half up, in 64-bit so the product cannot overflow.
constexpr int64_t MulShift(int64_t a, int64_t b, int s) {
  return (a * b + (int64_t{1} << (s - 1))) >> s;
}

}  // namespace lb::fx
