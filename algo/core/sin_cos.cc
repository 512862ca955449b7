#include "algo/core/sin_cos.h"

#include <cmath>

namespace lb {

void SinCosDeg(double degrees, double* s, double* c) {
  double turns = degrees / 360.0;
  turns -= std::floor(turns);  // [0, 1)
  double x = turns * 6.283185307179586;
  if (x > 3.141592653589793) x -= 6.283185307179586;  // [-pi, pi]
  double term = x, sum_s = 0.0;
  for (int k = 1; k < 22; k += 2) {
    sum_s += term;
    term *= -x * x / ((k + 1) * (k + 2));
  }
  term = 1.0;
  double sum_c = 0.0;
  for (int k = 0; k < 22; k += 2) {
    sum_c += term;
    term *= -x * x / ((k + 1) * (k + 2));
  }
  *s = sum_s;
  *c = sum_c;
}

}  // namespace lb
