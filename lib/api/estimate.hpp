// bodypoint: the error estimate of a run by step (ErrorEstimate, bodypoint.hpp), and what the flags of
// a run make of it. Internal to the API.
#pragma once

#include "bodypoint/bodypoint.hpp"

#include <functional>
#include <string>
#include <vector>

namespace bodypoint::detail {

/// Runs the body (the run's own, or its start moved by a rounding) with the same method under another way
/// of advancing time and other options (a request valid by construction: it is not checked again).
using Rerun = std::function<BodyResult(const Body& body, const Advance& how, const Options& options)>;

/// Sets r.error for the finished run r, asked for as `how` with `options`: the accuracy mode's own
/// estimate, a companion run's (bodypoint.hpp, ErrorEstimate), or why the run has none.
void estimate_error(BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                    const Options& options, const Rerun& rerun);

/// A fixed-step run's companion `level` levels finer (h/2^level, 2^level times the steps), the estimate
/// from the final states of the run and its first companion, and whether the second companion confirms
/// it (the difference falls as h^p): for a batch's lanes, which run them outside integrate().
FixedSteps fixed_companion(const FixedSteps& run, int level = 1);
ErrorEstimate fixed_step_estimate(const MethodInfo& m, const Body& body, const State& run, const State& companion);
/// Whether the second companion confirms e (ErrorEstimate::confirmed), its basis saying so: the differences
/// fall as the order says (min_fall), or at least geometrically, the estimate then raised to the bound
/// that gives (estimate.cpp, kGeometricFall).
void confirm(ErrorEstimate& e, double min_fall, const State& run, const State& first, const State& second);
void confirm(ErrorEstimate& e, const MethodInfo& m, const Body& body, const State& run, const State& first,
             const State& second);

/// Whether the estimate e is at the scene's rounding level (below kRoundingLevel, estimate.cpp), where the
/// companion pair can agree by chance: the run is repeated from start_moved_by_rounding and what the two
/// differ by is added (add_rounding_spread).
bool at_rounding_level(const ErrorEstimate& e);
/// The state s with R scaled by 1 + 4 eps and v by 1 - 4 eps: a start moved by a rounding.
State start_moved_by_rounding(State s);
/// Adds to e what the run's final state and its repeat's from the moved start differ by, and its cost.
void add_rounding_spread(ErrorEstimate& e, const State& run, const State& repeat, long force_evals, double wall_s);

/// The relative energy error of the state `end` of a run of `body` (NaN where E is not an integral).
double final_energy_error(const Body& body, const std::vector<Centre>& centres, const State& end);

/// An outcome in the light of the run's error estimate e (estimate.cpp): the heuristic flag
/// (unresolved) becomes a warning when the estimate is within both bounds and its companion resolved
/// the scene; the energy's flag when the final state's energy error final_rel_dE is within its bound
/// and accounted for by the estimate; an estimate above max_error makes an ok run inaccurate.
void settle(Outcome& outcome, std::string& reason, std::vector<std::string>& warnings, const ErrorEstimate& e,
            double max_error, double max_energy_error, double final_rel_dE);

}  // namespace bodypoint::detail
