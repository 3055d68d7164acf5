// bodypoint: Richardson's estimate of a run's error from a companion run of the same method (order p)
// whose step differs by a factor `ratio` > 1: the one rule behind the accuracy mode's search
// (search/ladder.cpp), the estimate of a run by step and the sweep's vector lanes (lib/api/estimate/).
// With x(h) = x* + C h^p, runs at h and h/ratio differ by C h^p (1 - ratio^-p) (docs/physics.md, "Error
// estimate"). Internal: not installed.
#pragma once

#include <cmath>

namespace bodypoint::adaptive {

/// The error of the finer of two runs whose final states are `difference` apart: difference / (ratio^p - 1).
inline double finer_run_error(double difference, double ratio, int p) {
  return difference / (std::pow(ratio, p) - 1.0);
}

/// The same at an order observed (not an integer): observed_order's.
inline double finer_run_error(double difference, double ratio, double q) {
  return difference / (std::pow(ratio, q) - 1.0);
}

/// The error of the coarser of the two: difference / (1 - ratio^-p), ratio^p times the finer run's.
inline double coarser_run_error(double difference, double ratio, int p) {
  return difference / (1.0 - std::pow(ratio, -p));
}

/// Orders above this are not told apart (observed_order's bracket).
inline constexpr double kMaxObservedOrder = 40.0;

/// The order q with which x(h) = x* + C h^q fits three runs at steps h1 > h2 > h3 whose final states differ
/// by d12 (runs 1 and 2) and d23 (runs 2 and 3): the root of (h1^q - h2^q)/(h2^q - h3^q) = d12/d23 (increasing
/// in q), by bisection on [0, kMaxObservedOrder]; r13 = h1/h3, r23 = h2/h3.
inline double observed_order(double d12, double d23, double r13, double r23) {
  if (!(d23 > 0.0)) return kMaxObservedOrder;
  const double target = d12 / d23;
  auto ratio = [&](double q) {
    const double a = std::pow(r13, q), b = std::pow(r23, q);
    return (a - b) / (b - 1.0);
  };
  double lo = 1e-3, hi = kMaxObservedOrder;
  if (ratio(lo) >= target) return 0.0;
  if (ratio(hi) <= target) return kMaxObservedOrder;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (ratio(mid) < target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace bodypoint::adaptive
