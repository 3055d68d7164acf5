// bodypoint: the fine companions of a run by step (estimate/parts.hpp): at h/2 (ds/2 with the same time-step
// constant, or a tenth of the tolerance per step), finer again where they do not refine the run, and a second and
// third one level finer that confirm a flagged run's estimate.
#include "estimate/parts.hpp"

#include "bodypoint/accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

namespace bodypoint::detail {
namespace {

/// A step-size-controlled method's companion runs at the tolerance per step over kTolRatio: its
/// global error is about 1/kTolRatio of the run's (the controllers aim at an error proportional to tol).
constexpr double kTolRatio = 10.0;

/// A time-transformed companion that takes fewer than this many times the run's steps did not refine it
/// (a controlled one: no more steps); it is refined again, up to kMaxCompanionLevels levels (estimate.hpp).
constexpr double kRefined = 1.5;

/// The smallest tolerance per step a companion is run with (run.cpp refuses smaller ones).
constexpr double kMinCompanionTol = 1e-15;

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

std::string fixed_basis(int p, double ratio) { return "companion run at h/" + short_number(ratio) + ", " + order_text(p); }

/// The companion `level` levels finer than the run `how` (level >= 1): h or ds over 2^level with the
/// run's time-step constant, a tolerance per step over 10^level; nullopt with `none` saying why there is
/// none.
std::optional<Companion> companion_of(const MethodInfo& m, const Body& body, const Advance& how, int level,
                                      std::string& none) {
  const double ratio = std::pow(kStepRatio, level);
  const int p = fixed_order(m, body);
  const double richardson = bodypoint::coarser_run_error(1.0, ratio, p);  // times what the two runs differ by
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
    if (is_exact_flow(m))  // the runs differ by rounding
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

/// Whether a companion that took `companion_steps` refines a run of `how` that took `run_steps`.
bool refines(const Advance& how, long run_steps, long companion_steps) {
  if (std::holds_alternative<FictitiousSteps>(how))
    return static_cast<double>(companion_steps) >= kRefined * static_cast<double>(run_steps);
  if (std::holds_alternative<ControlledSteps>(how)) return companion_steps > run_steps;
  return true;
}

/// A companion that broke down (diverged, failed, a non-finite state) at a finer step than the run's is
/// not "no estimate": the run's step does not resolve what the finer one could not get through either
/// (ttl-s4 at ds = 3 on the two-centre material pass ended at R = -1.8e9 where the answer is 149, its
/// companion at ds/2 failed, and the run read ok). The run is flagged unresolved, the companion's reason
/// quoted. A companion stopped on request, or ended at another stop event, did not break down.
void flag_broken_companion(BodyResult& r, const BodyResult& x, const std::string& basis) {
  if (!companion_broke_down(x) || (r.outcome != Outcome::ok && r.outcome != Outcome::inaccurate)) return;
  r.outcome = Outcome::unresolved;
  r.reason = "the " + basis + " broke down (" + (x.reason.empty() ? std::string(outcome_name(x.outcome)) : x.reason) +
             "): a finer step did not get through the scene, so this run's step does not resolve it and its error is unknown";
}

}  // namespace

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

/// A flagged run, one of fewer than kFewSteps, or one whose pair the coarse side disagrees with (`check_pair`):
/// a second companion one level finer than `f` tells whether the pair is in the asymptotic regime (confirm),
/// and bounds a run of a few steps, or a pair that agrees by chance.
void second_companion(BodyResult& r, const Body& body, const Advance& how, const Options& options, const Options& o,
                      const Rerun& rerun, const FineCompanion& f, bool check_pair) {
  ErrorEstimate& e = r.error;
  std::string none;
  const std::optional<Companion> next = companion_of(*r.method, body, how, f.level + 1, none);
  if (!next) return;
  const BodyResult y = rerun(body, next->how, o);
  e.force_evals += y.total_force_evals();
  e.wall_s += y.run.wall_s;
  const bool alike = ended_alike(r, options, y, o);
  if (alike) bound_by_second(e, *r.method, body, r.run.steps, check_pair, r.run.final, f.x.run.final, y.run.final);
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

bool checks_fine_pair(const MethodInfo& m, const std::vector<Centre>& centres, const RunResult& run,
                      const std::optional<double>& coarse_side, double fine) {
  return (coarse_side && *coarse_side > kAsymptoticSpread * fine) || run_past_coarse_margin(m, centres, run);
}

void bound_by_second(ErrorEstimate& e, const MethodInfo& m, const Body& body, long steps, bool check_pair, const State& run,
                     const State& first, const State& second) {
  const int p = fixed_order(m, body);
  // What the run differs by from the second companion, plus what the first may still be off by.
  const double near = bodypoint::state_distance(run, first);
  const double further = bodypoint::state_distance(first, second);
  const double bound = bodypoint::state_distance(run, second) + further;
  // A run of a few steps (a time-transformed run whose landing step spans the whole end time) is not in any
  // asymptotic regime (ttl-verlet at ds = 1 on the material pass: 1 step, 2.1e-5 off, estimated 4.0e-6 from a
  // companion of 2 steps; a second of 3 steps is 1.7e-5 from the run). Nor is a pair that agrees by chance
  // where the error's terms of two orders cancel near its step: asymptotically it differs ratio^p times what
  // the next pair does, and it differs less than 1/kAsymptoticSpread of that (attracting lp-euler at h = 0.02:
  // 1.0e-5 off, estimated 2.0e-6 from its h/2 pair, 1.0e-6 apart where the next is 3.6e-6). Where it falls as
  // the order says, the coarse side was outside its regime.
  const bool few = steps < kFewSteps;
  const bool by_chance = check_pair && kAsymptoticSpread * near < std::pow(kStepRatio, p) * further;
  if (!(few || by_chance) || !(bound > e.value)) return;
  e.value = bound;
  e.basis += few ? "; a run of " + std::to_string(steps) + " steps: raised to what a second companion one level "
                   "finer differs by from it and from the first"
                 : "; the pair differs less than the order predicts from the next (not asymptotic): raised to what a "
                   "second companion one level finer differs by from it and from the first";
}

void confirm(ErrorEstimate& e, double min_fall, const State& run, const State& first, const State& second) {
  if (!(second.R.allFinite() && second.v.allFinite())) {
    e.basis += "; a second companion one level finer did not end as the run did";
    return;
  }
  const double d1 = bodypoint::state_distance(run, first), d2 = bodypoint::state_distance(first, second);
  if (d1 >= min_fall * d2) {
    e.confirmed = true;
    e.basis += "; a second companion one level finer confirms it";
    return;
  }
  if (d1 >= kGeometricFall * d2) {
    const double bound = bodypoint::state_distance(run, second) + d2;
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
  const double d2 = bodypoint::state_distance(first, second), d3 = bodypoint::state_distance(second, third);
  if (!(d2 >= kGeometricFall * d3)) {
    e.basis += "; nor a third, one level finer again (its differences fall " + short_number(d2 / d3) + "x)";
    return;
  }
  e.value = std::max(e.value, bodypoint::state_distance(run, third) + d3);
  e.confirmed = true;
  e.basis += "; a third companion one level finer again: the finer differences fall " + short_number(d2 / d3) +
             "x, the estimate at least what the run differs by from the third plus what that may still be off by";
}

bool companion_broke_down(const BodyResult& x) {
  return !is_finite(x.run.final) || x.outcome == Outcome::diverged || x.outcome == Outcome::collision ||
         (x.outcome == Outcome::failed && x.reason != kStoppedOnRequest);
}

std::optional<SegmentCompanion> segment_companion(const MethodInfo& m, const Body& body, const Advance& how, int level,
                                                  std::string& none) {
  std::optional<Companion> c = companion_of(m, body, how, level, none);
  if (!c) return std::nullopt;
  // At fictitious steps each of the segment's steps is taken as 2^level, its landing step too: a segment shorter
  // than ds is one landing step, which a run at ds/2 takes as the same single step where the segment is shorter
  // than ds/2 (ttl-pefrl by auto at tol 1e-6 in 50 segments of 0.3, steps 0.27-0.63: read 9.8e-9 for 2.6e-8).
  const auto* f = std::get_if<FictitiousSteps>(&how);
  if (f != nullptr && !is_exact_flow(m)) {
    FictitiousSteps grouped = *f;
    grouped.group = f->group * static_cast<int>(std::lround(std::pow(kStepRatio, level)));
    c->how = grouped;
    c->basis += " (each of the run's steps as " + std::to_string(grouped.group / f->group) + ", its landing step too)";
  }
  return SegmentCompanion{std::move(c->how), c->factor, std::move(c->basis)};
}

bool companion_refines(const Advance& how, long run_steps, long companion_steps) {
  return refines(how, run_steps, companion_steps);
}

}  // namespace bodypoint::detail
