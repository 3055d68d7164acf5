// bodypoint: the error estimate of a run by step, and the flags in its light (estimate.hpp).
#include "estimate.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/adaptive/richardson.hpp"
#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/batch.hpp"
#include "bodypoint/detail/run_support.hpp"
#include "bodypoint/field.hpp"
#include "bodypoint/invariants.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>

namespace bodypoint::detail {
namespace {

// Each constant's measurement: docs/developers.md, "Tuned constants".

/// The companion of a fixed or fictitious step h runs at h / kStepRatio: it costs kStepRatio runs, and
/// its error is kStepRatio^-p of the run's, so what the two differ by is the run's error to within that fraction.
constexpr double kStepRatio = ErrorEstimate::kStepRatio;
/// A step-size-controlled method's companion runs at the tolerance per step over kTolRatio: its
/// global error is about 1/kTolRatio of the run's (the controllers aim at an error proportional to tol).
constexpr double kTolRatio = 10.0;
/// A time-transformed companion that takes fewer than this many times the run's steps did not refine it
/// (a controlled one: no more steps); it is refined again, up to kMaxCompanionLevels levels (ds/1024, tol/1e10).
constexpr double kRefined = 1.5;
constexpr int kMaxCompanionLevels = 10;
/// The smallest tolerance per step a companion is run with (run.cpp refuses smaller ones).
constexpr double kMinCompanionTol = 1e-15;

/// A final state whose relative energy error exceeds this many times its estimated error has an error
/// the estimate does not account for; below kEnergyRoundOff it is round-off.
constexpr double kEnergyPerState = 10.0;
constexpr double kEnergyRoundOff = 1e-12;

/// A run flagged unresolved may be kept on its estimate only where a second companion, one level finer,
/// shows the error falling as h^p: the first pair's difference is at least 2^(p - kOrderSlack) times the
/// second's (a step-size-controlled pair: kMinTolFall times), or kMaxFall times at any order (the first
/// companion's error is then at most an eighth of the run's). A pair that both alias the spin differ by
/// what aliasing leaves, not by the error.
constexpr double kOrderSlack = 1.0;
constexpr double kMaxFall = 8.0;
constexpr double kMinTolFall = 3.0;
/// Below the order's fall, differences that still fall by kGeometricFall per level converge at least
/// geometrically: the second companion is then off by at most what it differs by from the first, and the
/// run by at most what it differs by from the second plus that. The estimate is raised to that bound and
/// kept; the aliasing runs the flag exists for fall by less than 1.
constexpr double kGeometricFall = 2.0;
/// A run of fewer steps than this has no asymptotic regime of its own: a second companion bounds it too.
constexpr long kFewSteps = 4;

/// A companion run: how it advances, what its difference to the run is multiplied by, how it is named.
struct Companion {
  Advance how;
  double factor = 1.0;
  std::string basis;
  double min_fall = 1.0;  ///< what the difference must fall by at the next level to confirm the estimate
};

std::string order_text(int p) { return "order " + std::to_string(p); }
/// The order the estimate assumes: at least 1 (a method without a fixed order is taken as first order,
/// which makes its estimate twice the difference).
int fixed_order(const MethodInfo& m, const Body& body) { return std::max(1, adaptive::effective_order(m, body)); }

/// Where the method's flow is exact (the Kepler split on a material point about one Coulomb centre),
/// two runs differ by rounding alone, which no step refines: their whole difference is the estimate, not
/// a Richardson fraction of it (bound orbit to t = 300, kep-y8 h = 1: 7.0e-10 off, the pair 3.2e-10 apart,
/// estimated 1e-10 before).
bool flow_is_exact(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres) {
  const auto pulling = std::count_if(centres.begin(), centres.end(), [](const Centre& k) { return k.A != 0.0; });
  return m.traits.orbit_exact && body.p.B == 0.0 && pulling == 1 && !non_coulomb(centres);
}
constexpr const char* kExactFlowBasis = "the method's flow is exact on this scene: they differ by rounding, taken whole";
std::string fixed_basis(int p, double ratio) { return "companion run at h/" + short_number(ratio) + ", " + order_text(p); }

/// The companion `level` levels finer than the run `how` (level >= 1): h or ds over 2^level with the
/// run's time-step constant, a tolerance per step over 10^level; nullopt with `none` saying why there is
/// none.
std::optional<Companion> companion_of(const MethodInfo& m, const Body& body, const Advance& how, int level,
                                      std::string& none) {
  const double ratio = std::pow(kStepRatio, level);
  const int p = fixed_order(m, body);
  const double richardson = adaptive::coarser_run_error(1.0, ratio, p);  // times what the two runs differ by
  const double fall = std::min(kMaxFall, std::pow(kStepRatio, p - kOrderSlack));
  if (const auto* f = std::get_if<FixedSteps>(&how)) {
    if (static_cast<double>(f->steps) * ratio > 1e15) {
      none = "a companion at h/" + short_number(ratio) + " would take more steps than can be counted";
      return std::nullopt;
    }
    return Companion{FixedSteps{f->h / ratio, f->steps * static_cast<long>(ratio)}, richardson, fixed_basis(p, ratio), fall};
  }
  if (const auto* f = std::get_if<FictitiousSteps>(&how)) {
    if (f->end.index() != 0) {
      none = "a run of a number of fictitious steps ends at a time no companion run reaches";
      return std::nullopt;
    }
    const FictitiousSteps finer{f->ds / ratio, EndTime{f->t_end()}};
    const std::string at = "companion run at ds/" + short_number(ratio);
    if (m.traits.exact_in_fictitious_time)  // the runs differ by rounding
      return Companion{finer, 1.0, at + " (the KS flow is exact: they differ by rounding and the time equation)", 1.0};
    return Companion{finer, richardson, at + " and the same time-step constant, " + order_text(p), fall};
  }
  if (const auto* c = std::get_if<ControlledSteps>(&how)) {
    const double over = std::pow(kTolRatio, level), tol = c->tol / over;
    if (tol < kMinCompanionTol) {
      none = "a companion at tol/" + short_number(over) + " would ask for a tolerance per step below 1e-15";
      return std::nullopt;
    }
    return Companion{ControlledSteps{c->h0, c->t_end, tol}, 1.0 / (1.0 - 1.0 / over),
                     "companion run at tol/" + short_number(over) + " per step", kMinTolFall};
  }
  none = "no companion for this way of advancing time";
  return std::nullopt;
}

/// The coarse companion (CoarseCompanion, estimate.hpp) needs this many steps of the run: below, the
/// coarse run has no asymptotic regime of its own (kFewSteps), and the fine companion decides.
constexpr long kCoarseMinSteps = 16;
/// The coarse companion's estimate is trusted up to this value: a run estimated above it is near the end
/// of its own asymptotic regime, where the coarse run at twice the step may be beyond it (aliasing the
/// spin, unstable), which Richardson on the coarse side would take for the run's error; such runs are
/// estimated by the fine companion at h/2.
constexpr double kCoarseTrusted = 1e-5;
/// On the coarse side the order is taken as at most this: at twice the step a method of order 6 to 10
/// is rarely in its asymptotic regime where it matters; at order <= 4 Richardson's factor is kept.
constexpr int kCoarseMaxOrder = 4;
/// Where the flags' angles limit the ratio below 2 (a time-transformed run's coarse companion at 1.47 ds)
/// the order is taken as at most this. (An odd number of fixed steps, whose companion takes half as many
/// rounded up, asked for 2.)
constexpr int kCoarseMaxOrderBelow2 = 2;
/// The coarse companion's steps are kept this far inside the flags' limits (a step turning the spin by
/// pi, the direction to a centre by pi/2) that the run's own steps, scaled by the ratio, predict: a pair
/// whose coarse steps turn the spin by 2-2.8 rad is not asymptotic.
constexpr double kCoarseAngleMargin = 0.45;
/// Below this ratio the pair differs too little to measure the error (ratio^p - 1 small against their
/// rounding): the fine companion decides.
constexpr double kMinCoarseRatio = 1.25;

/// Whether a companion that took `companion_steps` refines a run of `how` that took `run_steps`.
bool refines(const Advance& how, long run_steps, long companion_steps) {
  if (std::holds_alternative<FictitiousSteps>(how))
    return static_cast<double>(companion_steps) >= kRefined * static_cast<double>(run_steps);
  if (std::holds_alternative<ControlledSteps>(how)) return companion_steps > run_steps;
  return true;
}

/// Whether a coarse companion that took `coarse_steps` is coarser than the run of `run_steps`: a
/// time-transformed pair whose steps were not cut by the ratio (the landing step, steps bound by
/// something else) is no Richardson pair; it must take at most 1 / (1 + (ratio - 1) / 2) of the steps,
/// as the fine companion must take kRefined = 1.5 times the run's at ratio 2.
bool coarser(const CoarseCompanion& c, long coarse_steps, long run_steps) {
  if (!std::holds_alternative<FictitiousSteps>(c.how)) return true;
  return static_cast<double>(run_steps) >= (1.0 + (c.ratio - 1.0) / 2.0) * static_cast<double>(coarse_steps);
}

bool stopped_by_event(const BodyResult& r, const Options& options) {
  return r.run.stopped && !r.events.empty() && options.events[r.events.back().event].stop;
}

/// What a companion observes: the invariants if the run tracked them (a run that observes no step merges
/// adjacent sub-steps, which changes its rounding: a sweep's vector lanes, which observe, then agree with
/// it bit for bit), the run's stop events, with the run's time-step constant (a pair compared by
/// Richardson must be one method); no samples, no bounds, no estimate of its own.
Options companion_options(const Body& body, const std::vector<Centre>& centres, const Advance& how,
                          const Options& options) {
  Options o;
  o.track_invariants = options.track_invariants;
  o.estimate_error = false;
  o.max_energy_error = std::numeric_limits<double>::infinity();
  o.max_error = std::numeric_limits<double>::infinity();
  o.omega_c = options.omega_c;
  o.cancel = options.cancel;
  if (const auto* f = std::get_if<FictitiousSteps>(&how); f && o.omega_c < 0.0)
    o.omega_c = adaptive::automatic_omega_c(body, centres, f->ds);
  // A run cut at a stop event is compared with its companion cut at the same event.
  for (const Event& ev : options.events)
    if (ev.stop) o.events.push_back(ev);
  return o;
}

/// Whether a companion ended as the run did (finite, at the same stop event).
bool ended_alike(const BodyResult& run, const Options& run_options, const BodyResult& x, const Options& o) {
  return x.outcome != Outcome::refused && x.outcome != Outcome::failed && x.run.final.R.allFinite() &&
         x.run.final.v.allFinite() && stopped_by_event(run, run_options) == stopped_by_event(x, o);
}

/// A companion that broke down (diverged, failed, a non-finite state) at a finer step than the run's is
/// not "no estimate": the run's step does not resolve what the finer one could not get through either
/// (ttl-s4 at ds = 3 on the two-centre material pass ended at R = -1.8e9 where the answer is 149, its
/// companion at ds/2 failed, and the run read ok). The run is flagged unresolved, the companion's reason
/// quoted. A companion stopped on request, or ended at another stop event, did not break down.
void flag_broken_companion(BodyResult& r, const BodyResult& x, const std::string& basis) {
  const bool finite = x.run.final.R.allFinite() && x.run.final.v.allFinite();
  const bool broke = !finite || x.outcome == Outcome::diverged || x.outcome == Outcome::collision ||
                     (x.outcome == Outcome::failed && x.reason != kStoppedOnRequest);
  if (!broke || (r.outcome != Outcome::ok && r.outcome != Outcome::inaccurate)) return;
  r.outcome = Outcome::unresolved;
  r.reason = "the " + basis + " broke down (" + (x.reason.empty() ? std::string(outcome_name(x.outcome)) : x.reason) +
             "): a finer step did not get through the scene, so this run's step does not resolve it and its error is unknown";
}

/// A companion difference below kRoundingLevel is at the scene's rounding level, where the pair can agree
/// by chance (one draw of the rounding each). There the estimate adds what kRoundingDraws - 1 more runs
/// differ from the run by, off the run's grid (off_grid) from its start moved by adaptive::kStartShift,
/// either way in turn, as the accuracy mode adds its rounding probes below the same level (tolerance.hpp,
/// kProbeBelowTol): repeats of the run (fine companions), or coarse runs (coarse companion: half a run
/// each; at fixed steps the companion's twin, its own steps from the start moved the other way, the two
/// lanes of one batch where the method has a kernel: coarse_lanes), and the sum is taken kRoundingBound
/// times (ErrorEstimate).
constexpr double kRoundingLevel = adaptive::kProbeBelowTol;

/// `draw(k)`: the k-th draw (k >= 1), from the start moved rounding_way(k); `o`: the draws' options;
/// `options`: the run's (its events index them); `what`: what they are, for the basis.
void add_rounding_draws(ErrorEstimate& e, const BodyResult& r, const Options& options, const Options& o,
                        const std::function<BodyResult(int)>& draw, const std::string& what) {
  if (!at_rounding_level(e)) return;
  for (int k = 1; k < ErrorEstimate::kRoundingDraws; ++k) {
    const BodyResult p = draw(k);
    if (!ended_alike(r, options, p, o)) {
      e.force_evals += p.total_force_evals();
      e.wall_s += p.run.wall_s;
      continue;
    }
    add_rounding_spread(e, r.run.final, p.run.final, p.total_force_evals(), p.run.wall_s, what);
  }
  bound_from_draws(e);
}

/// The k-th draw of the rounding (k = 0: the first) as a scalar run: from the start moved rounding_way(k),
/// advancing as how_of(k) (repeats off the run's grid, or the coarse companion and its draws: coarse_draw).
std::function<BodyResult(int)> rerun_draws(const Body& body, std::function<Advance(int)> how_of, const Options& o,
                                           const Rerun& rerun) {
  return [&body, how_of = std::move(how_of), &o, &rerun](int k) {
    Body moved = body;
    moved.s0 = start_moved_by_rounding(body.s0, rounding_way(k));
    return rerun(moved, how_of(k), o);
  };
}

/// The lanes of one batch (batch.hpp) are the coarse companion and its twin, its first rounding draw, where
/// the method has a batch kernel for the scene and the run stops at no event (a batch locates none): two lanes
/// cost about what one scalar run does, so the draw the rounding level asks for is nearly free. Each lane computes the scalar run's
/// bits (tests/lib/test_batch.cpp), judged as integrate() judges the scalar companion; the batch polls
/// the run's cancellation.
constexpr std::size_t kDrawLanes = 2;
static_assert(ErrorEstimate::kRoundingDraws == kDrawLanes, "the batch holds the companion and every further draw");

std::optional<std::vector<BodyResult>> coarse_lanes(const MethodInfo& m, const Body& body,
                                                    const std::vector<Centre>& centres, const CoarseCompanion& c,
                                                    const Options& oc) {
  const auto* f = std::get_if<FixedSteps>(&c.how);
  if (f == nullptr || !c.twin_draw || !oc.events.empty() || !batch::accepts(m, body, centres)) return std::nullopt;
  std::vector<batch::Member> members;
  for (std::size_t k = 0; k < kDrawLanes; ++k)
    members.push_back({body.p, start_moved_by_rounding(body.s0, rounding_way(static_cast<int>(k))), centres.front().A});
  std::vector<BodyResult> lanes(kDrawLanes);
  try {
    std::vector<RunResult> runs = batch::run(m, members, *f, kDrawLanes, oc.cancel);
    for (std::size_t k = 0; k < kDrawLanes; ++k) {
      lanes[k].method = &m;
      lanes[k].run = std::move(runs[k]);
      Health h = assess(lanes[k].run, checks_for(m, centres, oc.max_energy_error));
      lanes[k].outcome = h.outcome;
      lanes[k].reason = std::move(h.why);
    }
  } catch (const StoppedOnRequest&) {
    for (BodyResult& lane : lanes) lane.method = &m, lane.outcome = Outcome::failed, lane.reason = kStoppedOnRequest;
  }
  return lanes;
}

/// The estimate of the coarse companion where the run has one and it is trusted (true); otherwise its
/// cost is counted and the fine companion decides (false). A coarse run that breaks down or that the
/// run does not refine says nothing of the run; a flagged run is left to the fine pair, which can
/// confirm it.
bool estimated_by_coarse(BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                         const Options& options, const Options& o, const Rerun& rerun) {
  if (r.outcome == Outcome::unresolved) return false;
  const std::optional<CoarseCompanion> c =
      coarse_companion(*r.method, how, r.run.steps, coarse_ratio_limit(*r.method, centres, r.run));
  if (!c) return false;
  // The coarse run is held to the default flags whether or not the run tracks its invariants: a coarse
  // step that aliases the spin, skips past a centre or loses the energy can agree with the run by
  // chance (rk4 at h = 0.2 on two-centres-spin, 70 % off: its coarse companion 1.5e-5 away, 0.63 in energy).
  Options oc = o;
  oc.track_invariants = true;
  oc.max_energy_error = kCoarseEnergyBound;
  const auto draw = rerun_draws(body, [&c](int k) { return coarse_draw(*c, k); }, oc, rerun);
  std::optional<std::vector<BodyResult>> lanes = coarse_lanes(*r.method, body, centres, *c, oc);
  const BodyResult x = lanes ? std::move(lanes->front()) : draw(0);
  ErrorEstimate& e = r.error;
  e.force_evals += x.total_force_evals();
  e.wall_s += x.run.wall_s;
  // The batch's twin ran whether or not a draw is wanted. Unused, its share of the batch's time is the
  // companion's (the lanes run in the same instructions), and its evaluations are not the estimate's: a
  // run's estimate then counts what a sweep's batch of it counts, where twins run only when wanted.
  const auto lane_cost = [&](ErrorEstimate& to) {
    for (std::size_t k = 1; lanes && k < lanes->size(); ++k) to.wall_s += (*lanes)[k].run.wall_s;
  };
  std::optional<ErrorEstimate> coarse;
  if (x.outcome == Outcome::ok && ended_alike(r, options, x, oc) && coarser(*c, x.run.steps, r.run.steps))
    coarse = coarse_estimate(*r.method, body, centres, *c, r.run.final, x.run.final);
  if (!coarse || !at_rounding_level(*coarse)) lane_cost(coarse ? *coarse : e);
  if (!coarse) return false;
  coarse->force_evals += e.force_evals;
  coarse->wall_s += e.wall_s;
  e = std::move(*coarse);
  const std::string& what = coarse_draw_text(*c);
  if (lanes) add_rounding_draws(e, r, options, oc, [&](int k) { return std::move((*lanes)[static_cast<std::size_t>(k)]); }, what);
  else add_rounding_draws(e, r, options, oc, draw, what);
  return true;
}

}  // namespace

double coarse_ratio_limit(const MethodInfo& m, const std::vector<Centre>& centres, const RunResult& run) {
  if (!run.invariants) return kStepRatio;
  const Checks checks = checks_for(m, centres);
  double limit = kStepRatio;
  if (!checks.spin_exact && !checks.macro_steps && run.invariants->max_spin_angle > 0.0)
    limit = std::min(limit, kCoarseAngleMargin * kMaxSpinAngle / run.invariants->max_spin_angle);
  const double turn = std::acos(std::clamp(run.invariants->min_turn_cos, -1.0, 1.0));
  if (!checks.orbit_exact && !checks.macro_steps && turn > 0.0) limit = std::min(limit, kCoarseAngleMargin * kMaxTurnAngle / turn);
  return limit;
}

std::optional<CoarseCompanion> coarse_companion(const MethodInfo& m, const Advance& how, long run_steps, double max_ratio) {
  const double r = std::min(kStepRatio, max_ratio);
  if (run_steps < kCoarseMinSteps || !(r >= kMinCoarseRatio)) return std::nullopt;
  if (const auto* f = std::get_if<FixedSteps>(&how)) {
    // Whole steps to the same end: ceil(n / r) of them, at the step that lands there. Off the run's
    // grid (one step more) the pair is no Richardson pair where the error depends on where the steps
    // fall about a close approach: attracting-close lp-bm4 at h = 0.01, 3.6e-8 off, read 5.3e-10 for
    // 3.3e-8 on the grid; off it, 10 of the estimate ladder's estimates were more than 3x low, on it 4.
    const long n = f->steps, coarse = static_cast<long>(std::ceil(static_cast<double>(n) / r));
    const double ratio = static_cast<double>(n) / static_cast<double>(coarse);
    if (!(ratio >= kMinCoarseRatio)) return std::nullopt;
    return CoarseCompanion{FixedSteps{f->h * ratio, coarse}, ratio, r, true};
  }
  const auto* f = std::get_if<FictitiousSteps>(&how);
  if (f == nullptr || f->end.index() != 0 || m.traits.exact_in_fictitious_time) return std::nullopt;
  return CoarseCompanion{FictitiousSteps{f->ds * r, EndTime{f->t_end()}}, r, r, false};
}

const std::string& coarse_draw_text(const CoarseCompanion& c) {
  return c.twin_draw ? kCoarseTwinDraw : kCoarseRoundingDraw;
}

Advance coarse_draw(const CoarseCompanion& c, int k) {
  if (k == 0) return c.how;
  if (!c.twin_draw) return off_grid(c.how, k);
  return k == 1 ? c.how : off_grid(c.how, k - 1);
}

Advance off_grid(const Advance& how, int k) {
  if (const auto* f = std::get_if<FixedSteps>(&how))
    return FixedSteps{f->h * static_cast<double>(f->steps) / static_cast<double>(f->steps + k), f->steps + k};
  if (const auto* f = std::get_if<FictitiousSteps>(&how)) {
    FictitiousSteps moved = *f;
    moved.ds *= 1.0 + k * adaptive::kProbeShift;
    return moved;
  }
  return how;
}

double rounding_way(int k) { return k % 2 == 1 ? -1.0 : 1.0; }

void bound_from_draws(ErrorEstimate& e) {
  e.value *= ErrorEstimate::kRoundingBound;
  e.basis += "; taken " + short_number(ErrorEstimate::kRoundingBound) + " times: a bound from " +
             std::to_string(ErrorEstimate::kRoundingDraws) + " draws of the rounding";
}

std::optional<ErrorEstimate> coarse_estimate(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                                             const CoarseCompanion& c, const State& run, const State& coarse) {
  if (!(coarse.R.allFinite() && coarse.v.allFinite())) return std::nullopt;
  const int p = std::min(c.asked < kStepRatio ? kCoarseMaxOrderBelow2 : kCoarseMaxOrder, fixed_order(m, body));
  const double d = adaptive::state_distance(run, coarse);
  ErrorEstimate e;
  const bool h = std::holds_alternative<FixedSteps>(c.how);
  const std::string step = h ? "h" : "ds";
  const std::string ratio = short_number(c.ratio);
  e.basis = "companion run at " + (ratio == "2" ? "2" + step : step + " x " + ratio) +
            " from a start moved by a rounding, ";
  if (flow_is_exact(m, body, centres)) {
    e.value = d;
    e.basis += kExactFlowBasis;
    return e.value <= kCoarseTrusted ? std::optional<ErrorEstimate>(std::move(e)) : std::nullopt;
  }
  e.value = adaptive::finer_run_error(d, c.ratio, p);
  e.basis += order_text(p) + (p < fixed_order(m, body) ? " (at most " + std::to_string(p) + " on the coarse side)" : "");
  // Where the pair differs by the scene's rounding, that difference is not divided: the run's own
  // rounding is of its size (the two runs' roundings are independent draws, the moved start's growth one more).
  if (const double floor = std::min(d, kRoundingLevel); floor > e.value) {
    e.value = floor;
    e.basis += floor == d ? "; at the scene's rounding level: their whole difference"
                          : "; raised to the rounding level " + short_number(kRoundingLevel) + ", below which they may differ by rounding alone";
  }
  if (!(e.value <= kCoarseTrusted)) return std::nullopt;
  return e;
}

namespace {

/// Why a run by step gets no estimate from companions ("" where it gets one): not asked for, a run that
/// did not end (failed, stopped), a run its sink ended early.
std::string why_no_companion(const BodyResult& r, const Options& options) {
  if (!options.estimate_error) return "not asked for (estimate_error off)";
  if (r.outcome != Outcome::ok && r.outcome != Outcome::unresolved && r.outcome != Outcome::inaccurate)
    return "the run ended " + std::string(outcome_name(r.outcome));
  if (r.run.stopped && !stopped_by_event(r, options)) return "the run was ended early by its sink";
  return "";
}

/// A finer companion run and its level (h / 2^level).
struct FineCompanion {
  Companion c;
  BodyResult x;
  int level;
};

/// The finer companion of the run r. A companion that takes no more steps than the run does not refine
/// it: a time-transformed run whose steps are cut to land on t_end (one physical step ds/c beyond the
/// whole span), a controlled run whose tolerance does not bind (its steps grow at the controller's largest
/// rate from the first trial step: odeint-dopri5 at tol 1e-3 and 1e-4 on a far pass take the same 9 steps,
/// 2.9e-8 off). The companion is refined until it does, up to kMaxCompanionLevels; nullopt (r.error.basis saying
/// why, a companion that broke down flagged on r) where there is none.
std::optional<FineCompanion> finer_companion(BodyResult& r, const Body& body, const Advance& how, const Options& options,
                                             const Options& o, const Rerun& rerun) {
  ErrorEstimate& e = r.error;
  for (int level = 1;; ++level) {
    std::optional<Companion> c = companion_of(*r.method, body, how, level, e.basis);
    if (!c) return std::nullopt;
    BodyResult x = rerun(body, c->how, o);
    e.force_evals += x.total_force_evals();
    e.wall_s += x.run.wall_s;
    if (!ended_alike(r, options, x, o)) {
      e.basis = "the " + c->basis + " did not end as the run did" + (x.reason.empty() ? "" : " (" + x.reason + ")");
      flag_broken_companion(r, x, c->basis);
      return std::nullopt;
    }
    if (refines(how, r.run.steps, x.run.steps)) return FineCompanion{std::move(*c), std::move(x), level};
    if (level == kMaxCompanionLevels) {
      e.basis = "companions down to the " + c->basis + " took no more steps than the run";
      return std::nullopt;
    }
  }
}

/// A flagged run, or one of fewer than kFewSteps: a second companion one level finer than `f` tells whether
/// the pair is in the asymptotic regime (confirm), and bounds a run of a few steps.
void second_companion(BodyResult& r, const Body& body, const Advance& how, const Options& options, const Options& o,
                      const Rerun& rerun, const FineCompanion& f) {
  ErrorEstimate& e = r.error;
  std::string none;
  const std::optional<Companion> next = companion_of(*r.method, body, how, f.level + 1, none);
  if (!next) return;
  const BodyResult y = rerun(body, next->how, o);
  e.force_evals += y.total_force_evals();
  e.wall_s += y.run.wall_s;
  const bool alike = ended_alike(r, options, y, o);
  if (alike && r.run.steps < kFewSteps) {
    // A run of a few steps (a time-transformed run whose landing step spans the whole end time) is not in
    // any asymptotic regime: its estimate is at least what it differs by from the finer companion, plus
    // what that one may still be off by (ttl-verlet at ds = 1 on the material pass: 1 step, 2.1e-5 off,
    // estimated 4.0e-6 from a companion of 2 steps; a second of 3 steps is 1.7e-5 from the run).
    const double bound = adaptive::state_distance(r.run.final, y.run.final) + adaptive::state_distance(f.x.run.final, y.run.final);
    if (bound > e.value) {
      e.value = bound;
      e.basis += "; a run of " + std::to_string(r.run.steps) + " steps: raised to what a second companion one level "
                 "finer differs by from it and from the first";
    }
  }
  if (r.outcome != Outcome::unresolved) return;
  if (!alike) {
    e.basis += "; a second companion one level finer did not end as the run did";
    return;
  }
  confirm(e, f.c.min_fall, r.run.final, f.x.run.final, y.run.final);
  if (e.confirmed) return;
  const std::optional<Companion> last = companion_of(*r.method, body, how, f.level + 2, none);
  if (!last) return;
  const BodyResult z = rerun(body, last->how, o);
  e.force_evals += z.total_force_evals();
  e.wall_s += z.run.wall_s;
  if (ended_alike(r, options, z, o)) confirm_deeper(e, r.run.final, f.x.run.final, y.run.final, z.run.final);
  else e.basis += "; a third companion did not end as the run did";
}

}  // namespace

void estimate_error(BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                    const Options& options, const Rerun& rerun) {
  ErrorEstimate& e = r.error;
  if (r.accuracy) {
    e.value = r.accuracy->err_estimate;
    e.basis = "the accuracy mode's step search (" + r.accuracy->basis + ")";
    e.confirmed = true;
    return;
  }
  if (std::string why = why_no_companion(r, options); !why.empty()) {
    e.basis = std::move(why);
    return;
  }
  const Options o = companion_options(body, centres, how, options);
  if (estimated_by_coarse(r, body, centres, how, options, o, rerun)) return;
  const std::optional<FineCompanion> f = finer_companion(r, body, how, options, o, rerun);
  if (!f) return;
  e.value = f->c.factor * adaptive::state_distance(r.run.final, f->x.run.final);
  e.basis = f->c.basis;
  if (flow_is_exact(*r.method, body, centres)) {
    e.value = std::max(e.value, adaptive::state_distance(r.run.final, f->x.run.final));
    e.basis += "; " + std::string(kExactFlowBasis);
  }
  add_rounding_draws(e, r, options, o, rerun_draws(body, [&how](int k) { return off_grid(how, k); }, o, rerun),
                     kRepeatRoundingDraw);
  if (r.outcome == Outcome::unresolved || r.run.steps < kFewSteps) second_companion(r, body, how, options, o, rerun, *f);
}

bool at_rounding_level(const ErrorEstimate& e) { return e.value < kRoundingLevel; }

State start_moved_by_rounding(State s, double way) {
  s.R *= 1.0 + way * adaptive::kStartShift;
  s.v *= 1.0 - way * adaptive::kStartShift;
  return s;
}

void add_rounding_spread(ErrorEstimate& e, const State& run, const State& repeat, long force_evals, double wall_s,
                         const std::string& what) {
  e.force_evals += force_evals;
  e.wall_s += wall_s;
  if (!(repeat.R.allFinite() && repeat.v.allFinite())) return;
  const double spread = adaptive::state_distance(run, repeat);
  e.value += spread;
  e.basis += "; plus " + short_number(spread) + " from " + what + " (the estimate is at the scene's rounding level)";
}

FixedSteps fixed_companion(const FixedSteps& run, int level) {
  const double ratio = std::pow(kStepRatio, level);
  return FixedSteps{run.h / ratio, run.steps * static_cast<long>(ratio)};
}

void confirm(ErrorEstimate& e, double min_fall, const State& run, const State& first, const State& second) {
  if (!(second.R.allFinite() && second.v.allFinite())) {
    e.basis += "; a second companion one level finer did not end as the run did";
    return;
  }
  const double d1 = adaptive::state_distance(run, first), d2 = adaptive::state_distance(first, second);
  if (d1 >= min_fall * d2) {
    e.confirmed = true;
    e.basis += "; a second companion one level finer confirms it";
    return;
  }
  if (d1 >= kGeometricFall * d2) {
    const double bound = adaptive::state_distance(run, second) + d2;
    e.value = std::max(e.value, bound);
    e.confirmed = true;
    e.basis += "; a second companion one level finer: the differences fall " + short_number(d1 / d2) +
               "x, the estimate at least what the run differs by from it plus what it may still be off by";
    return;
  }
  e.basis += "; a second companion one level finer does not confirm it (the differences fall " + short_number(d1 / d2) +
             "x, the step's order asks " + short_number(min_fall) + "x)";
}

/// A flagged run whose first companion aliases the spin as it does (a step turning it by more than pi)
/// differs from it by what aliasing leaves, and the second's difference does not fall below that: lp-bm4
/// at h = 1 on two spinning centres (6.86 rad per step) is 8.1e-4 off, its companions at h/2, h/4, h/8
/// 2.7e-3, 2.6e-4, 2.4e-6 off, the differences 3.3e-3, 2.9e-3 (a fall of 1.1: not confirmed), then 2.6e-4
/// (a fall of 11). One level down the finer pair resolves the spin, and the run is bounded through it: at
/// most what it differs by from the third plus the third's last difference (falling at least
/// geometrically, the third's distance to the limit is at most that): 1.07e-3 there, where it was refused.
void confirm_deeper(ErrorEstimate& e, const State& run, const State& first, const State& second, const State& third) {
  if (!(third.R.allFinite() && third.v.allFinite())) {
    e.basis += "; a third companion did not end as the run did";
    return;
  }
  const double d2 = adaptive::state_distance(first, second), d3 = adaptive::state_distance(second, third);
  if (!(d2 >= kGeometricFall * d3)) {
    e.basis += "; nor a third, one level finer again (its differences fall " + short_number(d2 / d3) + "x)";
    return;
  }
  e.value = std::max(e.value, adaptive::state_distance(run, third) + d3);
  e.confirmed = true;
  e.basis += "; a third companion one level finer again: the finer differences fall " + short_number(d2 / d3) +
             "x, the estimate at least what the run differs by from the third plus what that may still be off by";
}

void confirm(ErrorEstimate& e, const MethodInfo& m, const Body& body, const State& run, const State& first,
             const State& second) {
  confirm(e, std::min(kMaxFall, std::pow(kStepRatio, fixed_order(m, body) - kOrderSlack)), run, first, second);
}

ErrorEstimate fixed_step_estimate(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                                  const State& run, const State& companion) {
  ErrorEstimate e;
  const int p = fixed_order(m, body);
  e.basis = fixed_basis(p, kStepRatio);
  if (!(companion.R.allFinite() && companion.v.allFinite())) {
    e.basis = "the " + e.basis + " did not end as the run did";
  } else if (flow_is_exact(m, body, centres)) {
    e.value = adaptive::state_distance(run, companion);
    e.basis = "companion run at h/2, " + std::string(kExactFlowBasis);
  } else {
    // As integrate()'s companion: its factor times the difference (not the difference over 1 - 2^-p,
    // which rounds otherwise: a sweep's lane and the same run alone were an ulp apart).
    e.value = adaptive::coarser_run_error(1.0, kStepRatio, p) * adaptive::state_distance(run, companion);
  }
  return e;
}

double final_energy_error(const Body& body, const std::vector<Centre>& centres, const State& end) {
  if (non_coulomb(centres)) return std::numeric_limits<double>::quiet_NaN();  // E is not an integral there
  const CentreList field{centres};
  const double scale = energy_scale(body.p, field, body.s0);
  const double dE = std::abs(energy(body.p, field, end) - energy(body.p, field, body.s0));
  return scale > 0.0 ? dE / scale : dE;
}

void settle(Outcome& outcome, std::string& reason, std::vector<std::string>& warnings, const ErrorEstimate& e,
            double max_error, double max_energy_error, double final_rel_dE) {
  if (!e.known()) return;
  const bool within = e.value <= max_error;
  const std::string kept = ", but the estimated error is " + short_number(e.value) + " (" + e.basis + "): kept";
  // The heuristic flag is overruled by an estimate within both bounds whose companion resolves what the
  // run did not: a pair that both alias the spin differ by what aliasing leaves, not by the error
  // (kep-ss10 at h = 0.5 and 0.25 on B = 0.9: 9.5 and 9.1 % off, 0.4 % apart).
  if (outcome == Outcome::unresolved && within && e.value <= max_energy_error && e.confirmed) {
    warnings.push_back(reason + kept);
    outcome = Outcome::ok;
    reason.clear();
    return;
  }
  // The energy's flag is a measurement: it is overruled only where the final state no longer shows it
  // (its energy error within the bound: a transient near a centre, as the two-centre pass at h = 0.2,
  // 5.4e-2 on the way and 0.33 % off at the end) and the estimate accounts for what it does show. An
  // estimate far below the final energy error was fooled (rk4 at h = 0.1 and 0.05 on B = 0.9 agree to
  // 1.8e-5, both 81 % off, the energy 69 % off at the end).
  if (outcome == Outcome::inaccurate && within && final_rel_dE <= max_energy_error &&
      final_rel_dE <= kEnergyPerState * e.value + kEnergyRoundOff) {
    warnings.push_back(reason + " on the way, " + short_number(final_rel_dE) + " at the end" + kept);
    outcome = Outcome::ok;
    reason.clear();
    return;
  }
  if (!within && outcome == Outcome::ok) {
    outcome = Outcome::inaccurate;
    reason = "the estimated relative error of the final state is " + short_number(e.value) + " (above the bound " +
             short_number(max_error) + "; " + e.basis + ")";
  }
}

}  // namespace bodypoint::detail

namespace bodypoint {

void check_error_bound(double max_error) {
  if (!(max_error > 0.0))
    throw Error("the bound on the estimated error max_error must be a number > 0 (infinity: no bound), got " +
                detail::short_number(max_error));
}

}  // namespace bodypoint
