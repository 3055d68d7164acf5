// bodypoint: the coarse companion of a run by step (estimate/parts.hpp, estimate.hpp CoarseCompanion): up to
// twice its step from its start moved by a rounding, half a run, Richardson on the coarse side; trusted only where
// the default flags pass it and its estimate is small.
#include "estimate/parts.hpp"

#include "bodypoint/accuracy.hpp"
#include "bodypoint/batch.hpp"
#include "bodypoint/detail/run_parts.hpp"

#include <algorithm>
#include <limits>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace bodypoint::detail {
namespace {

/// The coarse companion (CoarseCompanion, estimate.hpp) needs this many steps of the run: below, the
/// coarse run has no asymptotic regime of its own (kFewSteps), and the fine companion decides.
constexpr long kCoarseMinSteps = 16;

/// A step's share of a run's rounding level: an ulp of the state, relative (a long run's rounding grows at most
/// about linearly in its steps; above 4.5e5 steps this lifts the level above kRoundingLevel).
constexpr double kRoundingPerStep = std::numeric_limits<double>::epsilon();

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

/// A coarse pair in its asymptotic regime differs ratio^p - 1 times the run's error; two orders whose terms
/// cancel near twice the step make it differ by much less (attracting lp-euler at h = 0.01: 9.3e-6 off, its
/// coarse run at 0.02 1.0e-5 off the same way, read 1.0e-6; bound-orbit lp-rkn4 at h = 0.1: 9.6e-7 off,
/// read 1.2e-7). A second coarse run, the coarse run's own coarse companion, tells: the order the three
/// runs observe (bodypoint::observed_order) must lie within kObservedOrderSlack of the orders the estimate
/// assumes (below: the coarse side's order, capped; above: the method's own, which high orders may
/// show at coarse steps). There it observed 4.5 (order 1) and 8.7 (order 4).
constexpr double kObservedOrderSlack = 1.0;

/// The second coarse run is asked for where the pair's estimate is at least this: within a hundred times the
/// rounding level the pair's difference is partly rounding, and the order three runs observe says nothing.
constexpr double kSecondCoarseFrom = 100.0 * kRoundingLevel;

/// The rounding level of a run of `run_steps` steps: an ulp a step (kRoundingPerStep).
double run_rounding_level(long run_steps) { return static_cast<double>(run_steps) * kRoundingPerStep; }

/// Whether a coarse companion that took `coarse_steps` is coarser than the run of `run_steps`: a
/// time-transformed pair whose steps were not cut by the ratio (the landing step, steps bound by
/// something else) is no Richardson pair; it must take at most 1 / (1 + (ratio - 1) / 2) of the steps,
/// as the fine companion must take kRefined = 1.5 times the run's at ratio 2.
bool coarser(const CoarseCompanion& c, long coarse_steps, long run_steps) {
  if (!std::holds_alternative<FictitiousSteps>(c.how)) return true;
  return static_cast<double>(run_steps) >= (1.0 + (c.ratio - 1.0) / 2.0) * static_cast<double>(coarse_steps);
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
  std::vector<RunResult> runs = batch::run(m, members, *f, kDrawLanes, oc.cancel);
  if (runs.empty()) {  // stopped on request
    for (BodyResult& lane : lanes) lane.method = &m, lane.outcome = Outcome::failed, lane.reason = kStoppedOnRequest;
    return lanes;
  }
  for (std::size_t k = 0; k < kDrawLanes; ++k) {
    lanes[k].method = &m;
    lanes[k].run = std::move(runs[k]);
    judge(lanes[k], centres, oc);
  }
  return lanes;
}

/// The second coarse companion of a pair whose estimate would be trusted: the coarse run's own coarse
/// companion (within the angles the coarse run's steps allow), from the same moved start; the order the three
/// runs observe decides (kObservedOrderSlack). True where the pair is kept: the three agree with the order, or
/// the coarse run is too short for a second. A coarse run whose own steps turn the spin or the direction to a
/// centre as far as the angles allow no second, and a second coarse run that breaks down or ends otherwise, say
/// the pair is near the end of its regime: not kept (lp-bm4 at h = 0.1 on an attracting pass, 1.0e-11 off: its
/// coarse run at 2h, no second within the angles, is 4.2e-7 off, and the pair read 2.8e-8).
/// `shown`: whether the pair is kept only where the three runs observe its order (a coarse run too short for a
/// second, or a second that does not refine it, then keeps nothing).
bool coarse_pair_asymptotic(ErrorEstimate& e, const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                            const CoarseCompanion& c, const BodyResult& x, const BodyResult& r, const Options& options,
                            const Options& oc, const Rerun& rerun, bool shown = false) {
  const double limit = coarse_ratio_limit(m, centres, x.run);
  const std::optional<CoarseCompanion> c2 = coarse_companion(m, c.how, x.run.steps, limit);
  if (!c2) return !shown && !(limit < kMinCoarseRatio);
  const BodyResult y = rerun_draws(body, [&c2](int) { return c2->how; }, oc, rerun)(0);
  e.force_evals += y.total_force_evals();
  e.wall_s += y.run.wall_s;
  if (!(y.outcome == Outcome::ok && ended_alike(r, options, y, oc))) return false;
  if (!coarser(*c2, y.run.steps, x.run.steps)) return !shown;
  return observed_order_agrees(m, body, c, *c2, r.run.final, x.run.final, y.run.final, r.run.steps, e);
}

/// Raised to the rounding level (coarse_estimate), the estimate e stands unless three runs show the pair's order:
/// then the pair's difference is the truncation's, and Richardson reads it (the rounding draws added after still
/// count the rounding). With the raise, estimates of errors in (1e-12, 1e-10] read a median 4.9x high on the ladder.
void lift_rounding_raise(ErrorEstimate& e, const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                         const CoarseCompanion& c, const BodyResult& x, const BodyResult& r, const Options& options,
                         const Options& oc, const Rerun& rerun) {
  const std::optional<ErrorEstimate> unraised =
      coarse_estimate(m, body, centres, c, r.run.final, x.run.final, r.run.steps, false);
  if (!unraised || !(unraised->value < e.value)) return;
  ErrorEstimate trial = *unraised;
  if (coarse_pair_asymptotic(trial, m, body, centres, c, x, r, options, oc, rerun, true)) {
    e = std::move(trial);
    e.basis += ", so not raised to the rounding level " + short_number(kRoundingLevel);
    return;
  }
  if (trial.force_evals > unraised->force_evals) e.basis += "; a second coarse run did not show the pair's order";
  e.force_evals = trial.force_evals, e.wall_s = trial.wall_s;
}

}  // namespace

double coarse_side_of(const MethodInfo& m, const Body& body, const CoarseCompanion& c, const State& run, const State& coarse) {
  return bodypoint::finer_run_error(bodypoint::state_distance(run, coarse), c.ratio, fixed_order(m, body));
}

bool asks_second_coarse(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres, const ErrorEstimate& e) {
  return e.value >= kSecondCoarseFrom && !flow_is_exact(m, body, centres);
}

bool sharpened_by_second_coarse(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                                const CoarseCompanion& c, const ErrorEstimate& e) {
  const int p = fixed_order(m, body);
  const int assumed = std::min(c.asked < kStepRatio ? kCoarseMaxOrderBelow2 : kCoarseMaxOrder, p);
  return assumed < p && e.value > kRoundingLevel && e.value < kSecondCoarseFrom && !flow_is_exact(m, body, centres);
}

bool observed_order_agrees(const MethodInfo& m, const Body& body, const CoarseCompanion& c, const CoarseCompanion& c2,
                           const State& run, const State& coarse, const State& coarser, long run_steps, ErrorEstimate& e) {
  if (!(coarser.R.allFinite() && coarser.v.allFinite())) return false;
  const double q = bodypoint::observed_order(bodypoint::state_distance(coarse, coarser), bodypoint::state_distance(run, coarse),
                                            c.ratio * c2.ratio, c.ratio);
  const int p = fixed_order(m, body);
  const int assumed = std::min(c.asked < kStepRatio ? kCoarseMaxOrderBelow2 : kCoarseMaxOrder, p);
  if (!(q >= assumed - kObservedOrderSlack && q <= p + kObservedOrderSlack)) return false;
  e.basis += "; a second coarse run at " + short_number(c.ratio * c2.ratio) + " times the step: the three observe order " +
             short_number(q);
  // Above the capped order the three runs show the pair's own order: Richardson at it (up to the method's), floored
  // at the run's own rounding level (an ulp a step), not at kRoundingLevel: the three runs showing the order say the
  // difference is the truncation's, as where lift_rounding_raise lifts the raise, and below kRoundingLevel the
  // rounding draws are added (bound-orbit lp-kl8 at h = 0.1, order 7.99 seen, 2.36e-11 off: read 1e-10 at the
  // fixed floor; the ladder's 90th percentile went 2.14 -> 1.87, none more than 3x low). (At the cap, order-8
  // pairs in their regime read 17x high at twice the step, 20x at 1.5 times: 230 of the estimate ladder's 267
  // estimates more than 2x high.) Where the coarse run's own steps held the second back from its whole ratio (the
  // flags' angles), the pair is near the end of its regime: the order taken is kObservedOrderSlack below the one
  // seen (strong-spin kep-y8 at h = 0.02, its second coarse run at 1.49 times the first's: order 7.68 seen, 3.1e-6
  // off, read 6.7e-7 at 7.68, 1.35e-6 at 6.68).
  const double taken = std::min(static_cast<double>(p), c2.asked >= kStepRatio ? q : q - kObservedOrderSlack);
  if (taken > assumed) {
    const double d = bodypoint::state_distance(run, coarse);
    const double sharper = std::max(bodypoint::finer_run_error(d, c.ratio, taken), std::min(d, run_rounding_level(run_steps)));
    if (sharper < e.value) {
      e.value = sharper;
      e.basis += ", order " + short_number(taken) + " taken";
    }
  }
  return true;
}

/// The estimate of the coarse companion where the run has one and it is trusted (true); otherwise its
/// cost is counted and the fine companion decides (false). A coarse run that breaks down or that the
/// run does not refine says nothing of the run; a flagged run is left to the fine pair, which can
/// confirm it.
bool estimated_by_coarse(BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                         const Options& options, const Options& o, const Rerun& rerun, std::optional<double>& coarse_side) {
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
  std::optional<std::vector<BodyResult>> lanes =
      rerun.twin_lanes ? coarse_lanes(*r.method, body, centres, *c, oc) : std::nullopt;
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
  if (x.outcome == Outcome::ok && ended_alike(r, options, x, oc) && coarser(*c, x.run.steps, r.run.steps)) {
    coarse = coarse_estimate(*r.method, body, centres, *c, r.run.final, x.run.final, r.run.steps);
    coarse_side = coarse_side_of(*r.method, body, *c, r.run.final, x.run.final);
    if (coarse && asks_second_coarse(*r.method, body, centres, *coarse) &&
        !coarse_pair_asymptotic(*coarse, *r.method, body, centres, *c, x, r, options, oc, rerun)) {
      e.force_evals += coarse->force_evals;
      e.wall_s += coarse->wall_s;
      coarse.reset();
    } else if (coarse && sharpened_by_second_coarse(*r.method, body, centres, *c, *coarse)) {
      // Below kSecondCoarseFrom the capped estimate stands unless three runs show the pair's order.
      ErrorEstimate trial = *coarse;
      if (coarse_pair_asymptotic(trial, *r.method, body, centres, *c, x, r, options, oc, rerun)) coarse = std::move(trial);
      else coarse->force_evals = trial.force_evals, coarse->wall_s = trial.wall_s;
    } else if (coarse) {
      lift_rounding_raise(*coarse, *r.method, body, centres, *c, x, r, options, oc, rerun);
    }
  }
  if (!coarse || !at_rounding_level(*coarse)) lane_cost(coarse ? *coarse : e);
  if (!coarse) return false;
  coarse->force_evals += e.force_evals;
  coarse->wall_s += e.wall_s;
  e = std::move(*coarse);
  e.pair = ErrorEstimate::Pair{r.run.final, x.run.final, r.run.t_end, x.run.t_end};
  const std::string& what = coarse_draw_text(*c);
  if (lanes)
    add_rounding_draws(e, r, options, oc, [&](int k) { return std::move((*lanes)[static_cast<std::size_t>(k)]); }, what,
                       &x.run.final);
  else add_rounding_draws(e, r, options, oc, draw, what, &x.run.final);
  return true;
}

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

/// A run whose steps turn past the coarse margin between two of its force evaluations is, as the coarser run
/// of its fine pair, where a coarse pair was measured outside its regime (kCoarseAngleMargin): three-centres
/// ttl-verlet at ds = 0.2, one evaluation a step turning the spin by 2 rad, is 1.7e-4 off where its pair at
/// ds/2 read 4.3e-5 (the companion at ds/2 is 1.7e-4 off too, the next at ds/4 4.3e-5). A composition's
/// stages sample the field within the step: at the same 2 rad a step, ttl-pefrl (4 evaluations) and the
/// eighth-order ones are in their regime (logh-kl8 on the close scene: 2.1x for a 10 % larger ds, order 8's
/// 2.14x); per step instead of per evaluation the check made 788 more of the estimate ladder's runs dearer
/// and raised none that was low (docs/measurements.md, "Limits, measured").
bool run_past_coarse_margin(const MethodInfo& m, const std::vector<Centre>& centres, const RunResult& run) {
  return coarse_ratio_limit(m, centres, run) * std::max(1, m.evals_per_step) < 1.0;
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
  if (f == nullptr || f->end.index() != 0 || is_exact_flow(m)) return std::nullopt;
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

std::optional<ErrorEstimate> coarse_estimate(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                                             const CoarseCompanion& c, const State& run, const State& coarse, long run_steps,
                                             bool raised) {
  if (!(coarse.R.allFinite() && coarse.v.allFinite())) return std::nullopt;
  const int p = std::min(c.asked < kStepRatio ? kCoarseMaxOrderBelow2 : kCoarseMaxOrder, fixed_order(m, body));
  const double d = bodypoint::state_distance(run, coarse);
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
  e.value = bodypoint::finer_run_error(d, c.ratio, p);
  e.basis += order_text(p) + (p < fixed_order(m, body) ? " (at most " + std::to_string(p) + " on the coarse side)" : "");
  // Where the pair differs by the scene's rounding, that difference is not divided: the run's own
  // rounding is of its size (the two runs' roundings are independent draws, the moved start's growth one more).
  // The level is the run's own where its steps round more: a long run's rounding grows up to an ulp a step
  // (rk4 at h = 1e-5 over 20 on a spinning pass, 2e6 steps: 2.7e-10 off, read 1e-10 at the fixed level).
  // The raise to the fixed level covers pairs that differ by less than their truncation says (attracting lp-rkn4
  // at h = 0.02, 1.19e-10 off, its pair 3.8e-11 apart) and a run whose rounding alone is 10x its draws'
  // (bound-spin ttl-ss10 at ds = 0.1, 1.04e-11 off, read 1.0e-12 without it); a second coarse run that observes
  // the pair's order lifts it (estimated_by_coarse).
  const double level = std::max(raised ? kRoundingLevel : 0.0, run_rounding_level(run_steps));
  if (const double floor = std::min(d, level); floor > e.value) {
    e.value = floor;
    e.basis += floor == d ? "; at the scene's rounding level: their whole difference"
                          : "; raised to the rounding level " + short_number(level) + ", below which they may differ by rounding alone";
  }
  if (!(e.value <= kCoarseTrusted)) return std::nullopt;
  return e;
}

}  // namespace bodypoint::detail
