// Sine and cosine from +, * and / alone, so they round alike on x86-64, aarch64 and armhf: libm's
// sin and cos may differ in the last bit between C libraries and targets, and the aperture
// kernels and the synthetic scene are pinned bit for bit.
#pragma once

namespace lb {

// Of an angle in degrees: reduced to [-180, 180], then a Taylor series to the 21st power (error
// below 1e-9 over the whole turn, far less for small angles).
void SinCosDeg(double degrees, double* s, double* c);

}  // namespace lb
