// bodypoint: the error estimate of a run by step (ErrorEstimate, bodypoint.hpp), and what the flags of
// a run make of it. Internal to the API.
#pragma once

#include "bodypoint/bodypoint.hpp"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace bodypoint::detail {

/// How the estimate runs a companion: the body (the run's own, or its start moved by a rounding) with the same
/// method under another way of advancing time and other options (a request valid by construction: it is not
/// checked again). integrate() runs it as a scalar run (stage 3 of its pipeline); a sweep's batch as a lane
/// of a batch with the same companion of the other rows (sweep.cpp, LaneRuns): one policy, two runners.
struct Rerun {
  std::function<BodyResult(const Body& body, const Advance& how, const Options& options)> run;
  /// Whether the coarse companion and its twin (its first rounding draw) may run as the two lanes of a batch
  /// of their own (estimate/coarse.cpp): a scalar run's; a sweep's lanes batch them with the other rows'.
  bool twin_lanes = true;
  BodyResult operator()(const Body& body, const Advance& how, const Options& options) const {
    return run(body, how, options);
  }
};

/// Stages 4 and 5 of a run of a method resolved and accepted: r.error for the finished run r, asked for as
/// `how` with `options` (the accuracy mode's own estimate, the companions' of bodypoint.hpp's ErrorEstimate,
/// or why the run has none), its located events' errors (EventHit::t_error, r_error, state_error), and its
/// outcome settled in the light of the estimate (settle).
void estimate_and_settle(BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                         const Options& options, const Rerun& rerun);
/// The outcome of a finished run from its flags (assess with the options' bounds); invariants a run observed
/// for its events or samples alone, not asked for, are neither reported nor judged.
void judge(BodyResult& r, const std::vector<Centre>& centres, const Options& options);

/// A Stepper's companion over one segment `how` (forwards), `level` levels finer (fine.cpp, the fine companion:
/// h or ds over 2^level with the same time-step constant, a tolerance per step over 10^level): how it advances,
/// what its difference to the run is multiplied by, its basis; nullopt, `none` saying why, where there is none.
struct SegmentCompanion {
  Advance how;
  double factor = 1.0;
  std::string basis;
};
std::optional<SegmentCompanion> segment_companion(const MethodInfo& m, const Body& body, const Advance& how, int level,
                                                  std::string& none);
/// Whether a companion run broke down (a non-finite state, diverged, fell onto a centre, failed other than on
/// request): the run's step then does not resolve what a finer one could not get through (fine.cpp).
bool companion_broke_down(const BodyResult& x);
/// Whether a companion that took `companion_steps` refines a segment of `how` that took `run_steps` (fine.cpp:
/// a time-transformed one at least 1.5 times the steps, a controlled one more).
bool companion_refines(const Advance& how, long run_steps, long companion_steps);
/// A time-transformed companion that takes fewer than 1.5 times the run's steps did not refine it (a controlled
/// one: no more steps); it is refined again, up to this many levels (ds/1024, tol/1e10): a run's and a Stepper's.
inline constexpr int kMaxCompanionLevels = 10;

/// Whether the estimate e is at the scene's rounding level (below kRoundingLevel, estimate/parts.hpp), where the
/// companion pair can agree by chance: ErrorEstimate::kRoundingDraws - 1 more draws of the rounding are
/// added (add_rounding_spread): repeats of the run (fine companions) or coarse runs (coarse companion),
/// off the run's grid from its start moved by a rounding; the sum is taken ErrorEstimate::kRoundingBound
/// times where the draws repeat the run (bound_from_draws), as it is where they are coarse (sum_of_draws).
bool at_rounding_level(const ErrorEstimate& e);
/// What add_rounding_spread's draws are.
inline const std::string kRepeatRoundingDraw = "a repeat off the run's grid from its start moved by a rounding";
inline const std::string kCoarseRoundingDraw = "a coarse run off the run's grid from its start moved by a rounding";
inline const std::string kCoarseTwinDraw = "the coarse run from its start moved the other way";
/// `how` with its steps off its own grid (k fixed steps more; a fictitious step longer by a relative
/// k bodypoint::kProbeShift; a controlled run as it is): a draw of the rounding whose steps land nowhere the
/// first's do. Repeats at the same step share the rounding of every point they share (ttl-kl8, ds = 0.02
/// on a bound spinning orbit: coarse runs from starts moved either way 2e-13 and 1.5e-12 from a run
/// 1.1e-11 off; off the grid, 1.2e-11).
Advance off_grid(const Advance& how, int k = 1);
/// The way the k-th rounding draw moves its start (start_moved_by_rounding): the first draw, the run's
/// own companion, +1; then -1, +1, ...
double rounding_way(int k);
/// The estimate e, the pair's part `pair` plus what repeats of the run differ from it by, taken as a bound: the
/// repeats' part kRoundingBound times, its basis saying so. A repeat measured from the run is one draw of the
/// run's rounding, the margin a bound needs; the pair's part is not doubled, which where truncation dominates
/// read 2.0x the error (bench/estimate_ladder.py: 80 fine pairs at 2.0-2.6).
void bound_from_draws(ErrorEstimate& e, double pair);
/// The estimate e of a coarse pair summed with its coarse run's further draws, each measured from the coarse
/// run, taken as it is, its basis saying so: the pair's difference already holds two draws (the run's rounding
/// and the coarse run's), and a further one measures the coarse run's again (bench/estimate_ladder.py, the
/// doubled sum: 90th percentile 4.13, not doubled 2.81, none more than 3x low either way).
void sum_of_draws(ErrorEstimate& e);
/// The state s with R scaled by 1 + 4 eps and v by 1 - 4 eps (`way` -1: the other way): a start moved by a
/// rounding.
State start_moved_by_rounding(State s, double way = 1.0);
/// Adds to e what the run's final state and `repeat` (another draw of its rounding, made as `what` says)
/// differ by, and its cost.
void add_rounding_spread(ErrorEstimate& e, const State& run, const State& repeat, long force_evals, double wall_s,
                         const std::string& what = kRepeatRoundingDraw);

/// The relative energy error of the state `end` of a run of `body` (NaN where E is not an integral).
double final_energy_error(const Body& body, const std::vector<Centre>& centres, const State& end);

/// An outcome in the light of the run's error estimate e (estimate/settle.cpp): the heuristic flag
/// (unresolved) becomes a warning when the estimate is within both bounds and its companion resolved
/// the scene; the energy's flag when the final state's energy error final_rel_dE is within its bound
/// and accounted for by the estimate; an estimate above max_error makes an ok run inaccurate.
void settle(Outcome& outcome, std::string& reason, std::vector<std::string>& warnings, const ErrorEstimate& e,
            double max_error, double max_energy_error, double final_rel_dE);

}  // namespace bodypoint::detail
