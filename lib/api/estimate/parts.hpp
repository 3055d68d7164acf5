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
/// Adds kRoundingDraws - 1 draws of the rounding to e where it is at the rounding level (rounding.cpp).
void add_rounding_draws(ErrorEstimate& e, const BodyResult& r, const Options& options, const Options& o,
                        const std::function<BodyResult(int)>& draw, const std::string& what);
/// The k-th draw of the rounding as a scalar run (rounding.cpp).
std::function<BodyResult(int)> rerun_draws(const Body& body, std::function<Advance(int)> how_of, const Options& o,
                                           const Rerun& rerun);

}  // namespace bodypoint::detail
