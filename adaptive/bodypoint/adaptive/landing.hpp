// bodypoint: landing a step on a physical time: the root of t(s) - target over a step length s.
#pragma once

#include <cmath>

namespace bodypoint::adaptive {

/// Regula falsi with the Illinois safeguard on [lo, hi], where residual(lo) = f_lo < 0 < f_hi =
/// residual(hi): calls residual(s) (which may keep what it computed for s) until |residual| <= tol, at
/// most 60 times; returns the last s tried. Used where the physical time a step advances grows
/// monotonically and nearly linearly with its length (2-3 trials), so a step can end on a given time.
template <class Residual>
double land_step(Residual&& residual, double lo, double f_lo, double hi, double f_hi, double tol) {
  int side = 0;
  double s = lo;
  for (int it = 0; it < 60; ++it) {
    const double mid = lo - f_lo * (hi - lo) / (f_hi - f_lo);
    s = (mid > lo && mid < hi) ? mid : 0.5 * (lo + hi);
    const double f = residual(s);
    if (std::abs(f) <= tol) break;
    if (f > 0) {
      hi = s;
      f_hi = f;
      if (side == 1) f_lo *= 0.5;
      side = 1;
    } else {
      lo = s;
      f_lo = f;
      if (side == -1) f_hi *= 0.5;
      side = -1;
    }
  }
  return s;
}

}  // namespace bodypoint::adaptive
