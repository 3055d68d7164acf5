// bodypoint: the accuracy mode's rules that every layer reads (the request's checks, the limits and shares
// of its error model, Richardson's estimate, the time-step constant c), kept in the core so that the
// public API asks the adaptive layer for one thing only: a search (adaptive/tolerance.hpp). Internal:
// not installed.
#pragma once

#include "bodypoint/model.hpp"

#include <cmath>
#include <limits>
#include <string_view>
#include <vector>

namespace bodypoint {

/// Requested tolerances below this are refused: runs of 1e3..1e5 steps accumulate a round-off
/// floor of 1e-15..1e-13 relative (README, round-off floor test), so a smaller error cannot be
/// delivered, nor estimated, in double precision.
inline constexpr double kMinTolerance = 1e-13;
/// A step the search predicts, or a map plans (Accuracy::first_step), aims its estimate at this fraction of
/// tol: a prediction from a coarser pair is uncertain by a factor of a few, and a miss costs one more run.
inline constexpr double kTargetShare = 0.3;

/// Below this tolerance a run about to be delivered is repeated kProbeRuns times: with its roundings
/// changed (all but one), and once from its start moved by a rounding; what they differ by is added to the estimate
/// (adaptive/search/rounding.cpp): an encounter amplifies round-off, which Richardson's estimate cannot tell from
/// truncation. The search then costs that many delivered runs more. Above it a ladder whose estimates stalled
/// among runs that differ by round-off's amounts is probed too (search/ladder.cpp, deliverable()).
inline constexpr double kProbeBelowTol = 1e-10;
inline constexpr int kProbeRuns = 3;
/// The rounding probe's relative move of the starting state (R scaled by 1 + kStartShift, v by 1 -
/// kStartShift): a few units in the last place of a double (the rounding of a decimal input such as
/// Kz = 0.1 is half of one). The run-by-step estimate at the rounding level moves it alike (lib/api/estimate/rounding.cpp).
inline constexpr double kStartShift = 4.0 * std::numeric_limits<double>::epsilon();
/// The rounding probe's relative move of a fictitious step (k kProbeShift for its k-th repeat): its
/// steps then land nowhere the run's do, and its truncation error moves by far less than a tolerance.
/// The run-by-step estimate's second coarse draw moves its step alike (lib/api/estimate/rounding.cpp, off_grid).
inline constexpr double kProbeShift = 1e-9;

/// Why the accuracy mode refuses a scene with a centre that does not follow Coulomb's law.
inline constexpr std::string_view kNeedsCoulomb =
    "the accuracy mode (tol) assumes Coulomb's law (its error model and time transformations do); run the thesis "
    "code's force law with a fixed step h";

/// Throws Error unless tol is a finite number in [kMinTolerance, 1).
void check_tolerance(double tol);

/// The constant c of the time-step function of logh-* and ttl-*, chosen from the scene and the fictitious
/// step ds when RunOptions::omega_c < 0 (accuracy.cpp says why); 0 for a material point.
double automatic_omega_c(const Body& body, const std::vector<Centre>& centres, double ds);

// Richardson's estimate of a run's error from a companion run of the same method (order p) whose step
// differs by a factor `ratio` > 1: the one rule behind the accuracy mode's search (adaptive/search/ladder.cpp),
// the estimate of a run by step (lib/api/estimate/). With x(h) = x* + C h^p,
// runs at h and h/ratio differ by C h^p (1 - ratio^-p) (docs/physics.md, "Error estimate").

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

}  // namespace bodypoint
