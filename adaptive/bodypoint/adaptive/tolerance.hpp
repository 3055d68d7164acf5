// bodypoint: ask for an accuracy, not a step.
//
// `run_to_tolerance` integrates a body to t_end with a fixed-step or time-transformed method and
// chooses the step (h, or the fictitious step ds) so that the final state's relative error,
//   err = max(|R - R_exact|/|R_exact|, |v - v_exact|/|v_exact|),
// is at most tol. The global error is estimated by Richardson's principle from runs of the same
// method at different steps (E. Hairer, S. P. Norsett, G. Wanner, Solving Ordinary Differential
// Equations I, 2nd ed., Springer 1993, sec. II.4, "Richardson extrapolation" and its use for global
// error estimation): in the asymptotic regime err(h) = C h^p, so two runs at h and h/r differ by
// C h^p (1 - r^-p) and the finer one's error is their difference over r^p - 1. The run delivered is
// the run reported: it carries the observers (RunOptions), nothing is integrated again. The steps of
// the search: adaptive/search/ladder.cpp; each tuned constant's measurement: docs/measurements.md.
//
// `--method auto` (which method for a scene and a tol) is one layer up: bodypoint/methods.hpp.
#pragma once

#include "bodypoint/accuracy.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/detail/run_parts.hpp"

#include <optional>
#include <string>
#include <vector>

namespace bodypoint::adaptive {

struct ToleranceResult {
  RunResult result;        ///< the delivered run, with the invariants and samples RunOptions asked for
  double h = 0.0;          ///< the step used: h, or ds for time-transformed methods
  long steps = 0;          ///< fixed-step methods: number of steps (time-transformed: 0)
  double omega_c = 0.0;    ///< time-transformed methods: the time-step constant c of the run
  double err_estimate = 0.0;  ///< estimated relative error of the final state
  std::string basis;          ///< what the estimate is: Richardson over the ladder's runs, or a pair's difference
  int runs = 0;            ///< integrations made in all (the delivered run included)
  long total_force_evals = 0;  ///< over all those runs
  double total_wall_s = 0.0;   ///< step loops of all those runs (what a user waits for)
  /// The run at the step nearest the delivered one's (another step), at the same end: what the estimate's
  /// pair is (ErrorEstimate::pair), for the quantities a caller reads from the final state. None where no
  /// other step ran.
  struct Companion {
    State final;
    double t_end = 0.0;
  };
  std::optional<Companion> companion;
};

/// Checks the scene, the accuracy asked for (check_tolerance; t_end and dt_out: check), the options and
/// the method (fixed-step or time-transformed with a known order, ks or far-ip, accepting the scene), then
/// searches the step for a run from t = 0 to accuracy.t_end (search_step). The delivered run carries
/// `delivery`'s observers: its invariants, and its samples (every k-th step, or with dt_out the states
/// at t = k dt_out), handed to the sink after the search. Throws Error with a one-line reason when tol
/// cannot be met (round-off floor, a budget of force evaluations exceeded).
/// `verify`: as search_step's (false for a method auto chose).
ToleranceResult run_to_tolerance(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres,
                                 const Accuracy& accuracy, const RunOptions& delivery = {}, bool verify = true);
/// The search alone, for a request whose every part was checked already (integrate() checks each once).
/// With `verify` (a method the user named) the run about to be delivered is checked against a companion
/// at 1/1.25 of its step (kVerifyRatio, search/ladder.cpp), and the search goes on from that companion
/// when they disagree by more than tol: the ladder's own estimate can be fooled where the error is not
/// smooth in h (lp-kl8 at tol 1e-4 on a two-centre pass delivered 46x tol). `auto`'s choices about one
/// centre were measured honest without it.
ToleranceResult search_step(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres,
                            const Accuracy& accuracy, const RunOptions& delivery, bool verify = true);
/// Throws Error unless the accuracy mode can search `method`'s step: a fixed-step or time-transformed
/// method with a known order, or ks.
void check_searchable(const MethodInfo& method);

}  // namespace bodypoint::adaptive
