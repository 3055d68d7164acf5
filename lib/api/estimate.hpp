// bodypoint: the error estimate of a run by step (ErrorEstimate, bodypoint.hpp), and what the flags of
// a run make of it. Internal to the API.
#pragma once

#include "bodypoint/bodypoint.hpp"

#include <functional>
#include <optional>
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
/// Sets the errors of r's located events (EventHit::t_error, r_error, state_error) from one companion run at
/// twice the step (far-ip, KS: at 1/1.25 of it) that locates the same events, its evaluations the events';
/// nothing where r has no estimate or no step to scale (estimate/events.cpp).
void estimate_event_errors(BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                           const Options& options, const Rerun& rerun);

/// The coarse companion of a run by step: up to twice its step (h, or ds with the same time-step
/// constant; a fixed-step run of an odd number of steps: half as many rounded up, at the step that lands
/// on the same end), from its start moved by a rounding. It costs half a run; in the asymptotic regime it differs
/// from the run by the run's error times ratio^p - 1 (Richardson on the coarse side, the fine run
/// delivered), plus what the moved start grows to. nullopt where a run has none: step-size control, KS,
/// a counted number of fictitious steps, fewer than kCoarseMinSteps steps (estimate/coarse.cpp).
struct CoarseCompanion {
  Advance how;
  double ratio = 2.0;  ///< the companion's step over the run's
  double asked = 2.0;  ///< the ratio asked for: below 2 where the flags' angles limit it (coarse_ratio_limit)
  /// Whether its first rounding draw is its twin, its own steps from the start moved the other way (fixed
  /// steps: coarse_draw), so that the two are lanes of one batch.
  bool twin_draw = false;
};
/// The coarse companion is trusted only where the default flags pass it: no aliased spin, no skipped
/// centre, its energy within this bound.
constexpr double kCoarseEnergyBound = kDefaultMaxEnergyError;
/// ratio at most max_ratio (coarse_ratio_limit), nullopt below kMinCoarseRatio.
std::optional<CoarseCompanion> coarse_companion(const MethodInfo& m, const Advance& how, long run_steps, double max_ratio);
/// `how` with its steps off its own grid (k fixed steps more; a fictitious step longer by a relative
/// k bodypoint::kProbeShift; a controlled run as it is): a draw of the rounding whose steps land nowhere the
/// first's do. Repeats at the same step share the rounding of every point they share (ttl-kl8, ds = 0.02
/// on a bound spinning orbit: coarse runs from starts moved either way 2e-13 and 1.5e-12 from a run
/// 1.1e-11 off; off the grid, 1.2e-11).
Advance off_grid(const Advance& how, int k = 1);
/// How the k-th draw of the rounding of the coarse companion c advances (k = 0: c itself): its twin (c's
/// own steps, the start moved the other way) where c.twin_draw, else off_grid(c.how, k).
Advance coarse_draw(const CoarseCompanion& c, int k);
/// The way the k-th rounding draw moves its start (start_moved_by_rounding): the first draw, the run's
/// own companion, +1; then -1, +1, ...
double rounding_way(int k);
/// The estimate e, summed over ErrorEstimate::kRoundingDraws draws of the rounding, taken as a bound
/// (kRoundingBound times the sum), its basis saying so.
void bound_from_draws(ErrorEstimate& e);
/// The largest ratio at which the run's steps, scaled by it, stay inside the flags' angles (what its
/// invariants saw; kStepRatio where it tracked none).
double coarse_ratio_limit(const MethodInfo& m, const std::vector<Centre>& centres, const RunResult& run);
/// The estimate from the run's and the coarse companion's final states; nullopt where it is not trusted
/// (a coarse state not finite, an estimate above kCoarseTrusted, estimate/coarse.cpp): the fine companion decides.
std::optional<ErrorEstimate> coarse_estimate(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                                             const CoarseCompanion& c, const State& run, const State& coarse, long run_steps);
/// Whether a coarse pair whose estimate e would be trusted asks a second coarse companion: at 1e-8 or above
/// (kSecondCoarseFrom; nearer the rounding level the pair's difference is partly rounding), where the method's
/// flow is not exact (estimate/coarse.cpp).
bool asks_second_coarse(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres, const ErrorEstimate& e);
/// Whether a coarse pair whose estimate e is trusted below kSecondCoarseFrom asks a second coarse companion to
/// sharpen it: the order assumed on the coarse side is capped below the method's, and e is above the rounding
/// level; where the three runs observe a higher order, Richardson takes it (observed_order_agrees), where not, e stands.
bool sharpened_by_second_coarse(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                                const CoarseCompanion& c, const ErrorEstimate& e);
/// Whether a second coarse companion c2 (the coarse run's own, c2.ratio times its step) shows the pair (run,
/// coarse) in its asymptotic regime: the order the three final states observe lies within one of the orders
/// the estimate assumes (estimate/coarse.cpp, kObservedOrderSlack); where it does, e's basis says so.
bool observed_order_agrees(const MethodInfo& m, const Body& body, const CoarseCompanion& c, const CoarseCompanion& c2,
                           const State& run, const State& coarse, const State& coarser, ErrorEstimate& e);

/// What the coarse side reads of the run (Richardson on the pair at the method's order) where the coarse run
/// ended ok: compared with the fine pair's estimate (checks_fine_pair).
double coarse_side_of(const MethodInfo& m, const Body& body, const CoarseCompanion& c, const State& run, const State& coarse);
/// Whether a fine pair whose estimate is `fine` is checked by a second companion one level finer
/// (bound_by_second): the coarse side reads more than kAsymptoticSpread times it, or the run's own steps
/// turn past the angles a coarse companion's steps are held to (run_past_coarse_margin), so that the
/// pair's coarser run is where coarse pairs were measured outside their regime (estimate/fine.cpp).
bool checks_fine_pair(const MethodInfo& m, const std::vector<Centre>& centres, const RunResult& run,
                      const std::optional<double>& coarse_side, double fine);
/// Whether the run's own steps turn the spin, or the direction to a centre, past kCoarseAngleMargin of the
/// flags' angles between two of its force evaluations (coarse_ratio_limit times the evaluations a step below
/// 1): where a coarse companion's steps would not be trusted (estimate/coarse.cpp).
bool run_past_coarse_margin(const MethodInfo& m, const std::vector<Centre>& centres, const RunResult& run);
/// A run of fewer than kFewSteps steps, or a fine pair checks_fine_pair asks about (check_pair), given a second
/// companion one level finer: e is raised to what the run differs by from the second plus what the first
/// differs by from it, where the run is a few steps or its pair differs less than the order p predicts from
/// the next, p the method's order (estimate/fine.cpp).
void bound_by_second(ErrorEstimate& e, const MethodInfo& m, const Body& body, long steps, bool check_pair, const State& run,
                     const State& first, const State& second);
/// A run of fewer steps than this has no asymptotic regime of its own: a second companion bounds it too.
inline constexpr long kFewSteps = 4;

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

/// A fixed-step run's companion `level` levels finer (h/2^level, 2^level times the steps), the estimate
/// from the final states of the run and its first companion, and whether the second companion confirms
/// it (the difference falls as h^p): for a batch's lanes, which run them outside integrate().
FixedSteps fixed_companion(const FixedSteps& run, int level = 1);
ErrorEstimate fixed_step_estimate(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                                  const State& run, const State& companion);
/// Whether the second companion confirms e (ErrorEstimate::confirmed), its basis saying so: the differences
/// fall as the order says (min_fall), or at least geometrically, the estimate then raised to the bound
/// that gives (estimate/fine.cpp, kGeometricFall).
void confirm(ErrorEstimate& e, double min_fall, const State& run, const State& first, const State& second);
void confirm(ErrorEstimate& e, const MethodInfo& m, const Body& body, const State& run, const State& first,
             const State& second);
/// A flagged run that confirm() left unconfirmed, given a third companion one level finer again: where the
/// finer companions' differences fall at least geometrically, the run is off by at most what it differs by
/// from the third plus what the third may still be off by; e is raised to that and confirmed (estimate/fine.cpp).
void confirm_deeper(ErrorEstimate& e, const State& run, const State& first, const State& second, const State& third);

/// Whether the estimate e is at the scene's rounding level (below kRoundingLevel, estimate/parts.hpp), where the
/// companion pair can agree by chance: ErrorEstimate::kRoundingDraws - 1 more draws of the rounding are
/// added (add_rounding_spread): repeats of the run (fine companions) or coarse runs (coarse companion),
/// off the run's grid from its start moved by a rounding; the sum is taken ErrorEstimate::kRoundingBound
/// times.
bool at_rounding_level(const ErrorEstimate& e);
/// What add_rounding_spread's draws are.
inline const std::string kRepeatRoundingDraw = "a repeat off the run's grid from its start moved by a rounding";
inline const std::string kCoarseRoundingDraw = "a coarse run off the run's grid from its start moved by a rounding";
inline const std::string kCoarseTwinDraw = "the coarse run from its start moved the other way";
/// What the coarse companion c's rounding draws are (kCoarseTwinDraw for its twin).
const std::string& coarse_draw_text(const CoarseCompanion& c);
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
