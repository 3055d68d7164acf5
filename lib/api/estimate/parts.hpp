// bodypoint: the parts of the error estimate of a run by step (estimate.hpp), one concern per file:
//   estimate.cpp           which companion decides, in what order (estimate_error), and what a companion observes
//   estimate/coarse.cpp    the coarse companion at up to twice the step (half a run)
//   estimate/fine.cpp      the fine companions at h/2, h/4, ... and what they confirm of a flagged run
//   estimate/rounding.cpp  the rounding draws at the scene's rounding level
//   estimate/settle.cpp    what a run's flags make of its estimate
//   estimate/events.cpp    the located events' errors, from companions that locate them too
// Each tuned constant's measurement: docs/measurements.md, "Tuned constants". Internal to the API.
#pragma once

#include "estimate.hpp"

#include "bodypoint/accuracy.hpp"
#include "bodypoint/detail/run_support.hpp"

#include <algorithm>
#include <functional>
#include <optional>
#include <string>

namespace bodypoint::detail {

/// The companion of a fixed or fictitious step h runs at h / kStepRatio: it costs kStepRatio runs, and
/// its error is kStepRatio^-p of the run's, so what the two differ by is the run's error to within that fraction.
inline constexpr double kStepRatio = ErrorEstimate::kStepRatio;
/// Sets r.error for the finished run r, asked for as `how` with `options`: the accuracy mode's own
/// estimate, a companion run's (bodypoint.hpp, ErrorEstimate), or why the run has none (estimate.cpp).
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
/// How the k-th draw of the rounding of the coarse companion c advances (k = 0: c itself): its twin (c's
/// own steps, the start moved the other way) where c.twin_draw, else off_grid(c.how, k).
Advance coarse_draw(const CoarseCompanion& c, int k);
/// What the coarse companion c's rounding draws are (kCoarseTwinDraw for its twin).
const std::string& coarse_draw_text(const CoarseCompanion& c);
/// The largest ratio at which the run's steps, scaled by it, stay inside the flags' angles (what its
/// invariants saw; kStepRatio where it tracked none).
double coarse_ratio_limit(const MethodInfo& m, const std::vector<Centre>& centres, const RunResult& run);
/// The estimate from the run's and the coarse companion's final states; nullopt where it is not trusted
/// (a coarse state not finite, an estimate above kCoarseTrusted, estimate/coarse.cpp): the fine companion decides.
/// `raised`: below the rounding level kRoundingLevel the estimate is raised to the pair's whole difference (up
/// to the level); without, only to the level of the run's own steps' rounding (an ulp a step), which
/// estimated_by_coarse takes where a second coarse run shows the pair's order.
std::optional<ErrorEstimate> coarse_estimate(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                                             const CoarseCompanion& c, const State& run, const State& coarse, long run_steps,
                                             bool raised = true);
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
/// the estimate assumes (estimate/coarse.cpp, kObservedOrderSlack); where it does, e's basis says so. `run_steps`:
/// the run's steps, whose rounding level (an ulp a step) bounds e below.
bool observed_order_agrees(const MethodInfo& m, const Body& body, const CoarseCompanion& c, const CoarseCompanion& c2,
                           const State& run, const State& coarse, const State& coarser, long run_steps, ErrorEstimate& e);

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

/// Whether the second companion confirms e (ErrorEstimate::confirmed), its basis saying so: the differences
/// fall as the order says (min_fall), or at least geometrically, the estimate then raised to the bound
/// that gives (estimate/fine.cpp, kGeometricFall).
void confirm(ErrorEstimate& e, double min_fall, const State& run, const State& first, const State& second);
/// A flagged run that confirm() left unconfirmed, given a third companion one level finer again: where the
/// finer companions' differences fall at least geometrically, the run is off by at most what it differs by
/// from the third plus what the third may still be off by; e is raised to that and confirmed (estimate/fine.cpp).
void confirm_deeper(ErrorEstimate& e, const State& run, const State& first, const State& second, const State& third);


/// A companion difference below kRoundingLevel is at the scene's rounding level, where the pair can agree
/// by chance (one draw of the rounding each). There the estimate adds what kRoundingDraws - 1 more runs
/// differ from the run by, off the run's grid (off_grid) from its start moved by bodypoint::kStartShift,
/// either way in turn, as the accuracy mode adds its rounding probes below the same level (tolerance.hpp,
/// kProbeBelowTol): repeats of the run (fine companions), or coarse runs (coarse companion: half a run
/// each; at fixed steps the companion's twin, its own steps from the start moved the other way, the two
/// lanes of one batch where the method has a kernel: coarse_lanes), and the sum is taken kRoundingBound
/// times (ErrorEstimate).
inline constexpr double kRoundingLevel = bodypoint::kProbeBelowTol;
inline constexpr const char* kExactFlowBasis = "the method's flow is exact on this scene: they differ by rounding, taken whole";

inline std::string order_text(int p) { return "order " + std::to_string(p); }
/// The order the estimate assumes: at least 1 (a method without a fixed order is taken as first order,
/// which makes its estimate twice the difference).
inline int fixed_order(const MethodInfo& m, const Body& body) { return std::max(1, effective_order(m, body)); }

/// Where the method's flow is exact (the Kepler split on a material point about one Coulomb centre), two runs
/// differ by rounding alone: their whole difference is the estimate (estimate.cpp).
bool flow_is_exact(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres);
/// What a companion of the run asked as `how` observes: the invariants if the run tracked them, the run's stop
/// events, its time-step constant c; no samples, no bounds, no estimate of its own (estimate.cpp).
Options companion_options(const Body& body, const std::vector<Centre>& centres, const Advance& how, const Options& options);
/// Whether the run r ended at one of its stop events.
bool stopped_by_event(const BodyResult& r, const Options& options);
/// Whether a companion ended as the run did (finite, at the same stop event).
bool ended_alike(const BodyResult& run, const Options& run_options, const BodyResult& x, const Options& o);

/// A companion run: how it advances, what its difference to the run is multiplied by, how it is named.
struct Companion {
  Advance how;
  double factor = 1.0;
  std::string basis;
  double min_fall = 1.0;  ///< what the difference must fall by at the next level to confirm the estimate
};

/// A finer companion run and its level (h / 2^level).
struct FineCompanion {
  Companion c;
  BodyResult x;
  int level;
};

/// The finer companion of the run r (fine.cpp); nullopt, r.error.basis saying why, where there is none.
std::optional<FineCompanion> finer_companion(BodyResult& r, const Body& body, const Advance& how, const Options& options,
                                             const Options& o, const Rerun& rerun);
/// A flagged run, one of fewer than kFewSteps, or one whose fine pair the coarse side disagrees with
/// (`check_pair`): a second companion one level finer than f (fine.cpp).
void second_companion(BodyResult& r, const Body& body, const Advance& how, const Options& options, const Options& o,
                      const Rerun& rerun, const FineCompanion& f, bool check_pair);
/// The estimate of the coarse companion where the run has one and it is trusted (true; coarse.cpp). Where it
/// is not, but the coarse run ended as the run did, `coarse_side` is that pair's Richardson at the method's
/// order, to compare with the fine pair's.
bool estimated_by_coarse(BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                         const Options& options, const Options& o, const Rerun& rerun, std::optional<double>& coarse_side);
/// Asymptotically a pair differs ratio^p times what the next finer pair does, and the coarse side's
/// Richardson at the method's order reads what the fine side's does; beyond this factor either the coarse
/// run is outside its regime or the fine pair agrees by chance, and a second fine companion tells which
/// (second_companion's check).
inline constexpr double kAsymptoticSpread = 4.0;
/// Adds kRoundingDraws - 1 draws of the rounding to e where it is at the rounding level (rounding.cpp):
/// repeats of the run measured from it (`coarse` nullptr), the sum taken as a bound (bound_from_draws); or
/// draws of the coarse companion measured from its final state `coarse`, the sum as it is (sum_of_draws).
void add_rounding_draws(ErrorEstimate& e, const BodyResult& r, const Options& options, const Options& o,
                        const std::function<BodyResult(int)>& draw, const std::string& what,
                        const State* coarse = nullptr);
/// The k-th draw of the rounding as a scalar run (rounding.cpp).
std::function<BodyResult(int)> rerun_draws(const Body& body, std::function<Advance(int)> how_of, const Options& o,
                                           const Rerun& rerun);

}  // namespace bodypoint::detail
