// bodypoint: Richardson's estimate of a run's error from a companion run of the same method (order p)
// whose step differs by a factor `ratio` > 1: the one rule behind the accuracy mode's search
// (search/ladder.cpp), the estimate of a run by step and the sweep's vector lanes (lib/api/estimate.cpp).
// With x(h) = x* + C h^p, runs at h and h/ratio differ by C h^p (1 - ratio^-p) (docs/physics.md, "Error
// estimate"). Internal: not installed.
#pragma once

#include <cmath>

namespace bodypoint::adaptive {

/// The error of the finer of two runs whose final states are `difference` apart: difference / (ratio^p - 1).
inline double finer_run_error(double difference, double ratio, int p) {
  return difference / (std::pow(ratio, p) - 1.0);
}

/// The error of the coarser of the two: difference / (1 - ratio^-p), ratio^p times the finer run's.
inline double coarser_run_error(double difference, double ratio, int p) {
  return difference / (1.0 - std::pow(ratio, -p));
}

}  // namespace bodypoint::adaptive
