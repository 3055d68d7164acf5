// bodypoint: ask for an accuracy, not a step.
//
// `run_to_tolerance` integrates a body to t_end with a fixed-step or time-transformed method and
// chooses the step (h, or the fictitious step ds) so that the final state's relative error,
//   err = max(|R - R_exact|/|R_exact|, |v - v_exact|/|v_exact|),
// is at most tol. The global error is estimated by Richardson's principle from runs of the same
// method at different steps (E. Hairer, S. P. Norsett, G. Wanner, Solving Ordinary Differential
// Equations I, 2nd ed., Springer 1993, sec. II.4, "Richardson extrapolation" and its use for global
// error estimation): in the asymptotic regime err(h) = C h^p, so two runs at h and h/r differ by
// C h^p (1 - r^-p) and the finer one's error is their difference over r^p - 1. The estimate is only
// trusted where the ladder shows the asymptotic regime: the ratio of successive differences must be
// close to 2^p (a converging ladder whose ratio is below 2^p is given its measured rate instead,
// which makes the estimate larger). See tolerance.cpp for the steps of the search.
//
// `--method auto` (which method for a scene and a tol) is one layer up: bodypoint/methods.hpp.
#pragma once

#include "bodypoint/run.hpp"

#include <string>
#include <string_view>
#include <vector>

namespace bodypoint::adaptive {

/// Requested tolerances below this are refused: runs of 1e3..1e5 steps accumulate a round-off
/// floor of 1e-15..1e-13 relative (README, round-off floor test), so a smaller error cannot be
/// delivered, nor estimated, in double precision.
inline constexpr double kMinTolerance = 1e-13;

/// Why the accuracy mode refuses a scene with a centre that does not follow Coulomb's law.
inline constexpr std::string_view kNeedsCoulomb =
    "the accuracy mode (tol) assumes Coulomb's law (its error model and time transformations do); run the thesis "
    "code's force law with a fixed step h";

struct ToleranceResult {
  RunResult result;        ///< the delivered run (no invariants, no samples: see delivered_spec)
  double h = 0.0;          ///< the step used: h, or ds for time-transformed methods
  long steps = 0;          ///< fixed-step methods: number of steps (time-transformed: 0)
  double omega_c = 0.0;    ///< time-transformed methods: the time-step constant c of the run
  double err_estimate = 0.0;  ///< estimated relative error of the final state
  int runs = 0;            ///< integrations made to choose the step and estimate the error
  long total_force_evals = 0;  ///< over all those runs
  double total_wall_s = 0.0;   ///< step loops of all those runs (what a user waits for)
};

/// Validates tol (finite, >= kMinTolerance, < 1) and the method (fixed-step or time-transformed with
/// a known order, or ks), then searches the step for a run from t = 0 to t_end. Throws Error with a
/// one-line reason when tol cannot be met (round-off floor, a budget of force evaluations exceeded).
ToleranceResult run_to_tolerance(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres,
                                 double tol, double t_end);

/// `base` with the step of `r` filled in (h and steps, or ds and t_end): run() with it repeats the
/// delivered run, e.g. with invariants tracked or a sink.
RunSpec delivered_spec(const MethodInfo& method, const ToleranceResult& r, double t_end, RunSpec base);

/// Relative distance of two final states: max(|dR|/|R_b|, |dv|/|v_b|).
double state_distance(const State& a, const State& b);

/// Throws Error unless tol is a finite number in [kMinTolerance, 1).
void check_tolerance(double tol);

}  // namespace bodypoint::adaptive
