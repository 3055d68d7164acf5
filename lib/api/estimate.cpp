// bodypoint: the error estimate of a run by step (estimate.hpp): the accuracy mode's own, or the coarse companion's
// where it is trusted, or the fine companions', with the rounding draws at the rounding level. The parts, one
// concern per file: estimate/parts.hpp.
#include "estimate/parts.hpp"

#include "bodypoint/accuracy.hpp"
#include "bodypoint/field.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <limits>
#include <string>

namespace bodypoint::detail {
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

}  // namespace

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
    o.omega_c = bodypoint::automatic_omega_c(body, centres, f->ds);
  // A run cut at a stop event is compared with its companion cut at the same event.
  for (const Event& ev : options.events)
    if (ev.stop) o.events.push_back(ev);
  return o;
}

/// Where the method's flow is exact (the Kepler split on a material point about one Coulomb centre),
/// two runs differ by rounding alone, which no step refines: their whole difference is the estimate, not
/// a Richardson fraction of it (bound orbit to t = 300, kep-y8 h = 1: 7.0e-10 off, the pair 3.2e-10 apart,
/// estimated 1e-10 before).
bool flow_is_exact(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres) {
  const auto pulling = std::count_if(centres.begin(), centres.end(), [](const Centre& k) { return k.A != 0.0; });
  return m.traits.orbit_exact && body.p.B == 0.0 && pulling == 1 && !non_coulomb(centres);
}

bool stopped_by_event(const BodyResult& r, const Options& options) {
  return r.run.stopped && !r.events.empty() && options.events[r.events.back().event].stop;
}

/// Whether a companion ended as the run did (finite, at the same stop event).
bool ended_alike(const BodyResult& run, const Options& run_options, const BodyResult& x, const Options& o) {
  return ran(x.outcome) && x.run.final.R.allFinite() &&
         x.run.final.v.allFinite() && stopped_by_event(run, run_options) == stopped_by_event(x, o);
}

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
  std::optional<double> coarse_side;
  if (estimated_by_coarse(r, body, centres, how, options, o, rerun, coarse_side)) return;
  const std::optional<FineCompanion> f = finer_companion(r, body, how, options, o, rerun);
  if (!f) return;
  e.value = f->c.factor * bodypoint::state_distance(r.run.final, f->x.run.final);
  e.pair = ErrorEstimate::Pair{r.run.final, f->x.run.final, r.run.t_end, f->x.run.t_end};
  e.basis = f->c.basis;
  if (flow_is_exact(*r.method, body, centres)) {
    e.value = std::max(e.value, bodypoint::state_distance(r.run.final, f->x.run.final));
    e.basis += "; " + std::string(kExactFlowBasis);
  }
  add_rounding_draws(e, r, options, o, rerun_draws(body, [&how](int k) { return off_grid(how, k); }, o, rerun),
                     kRepeatRoundingDraw);
  // A fine pair the coarse side disagrees with, or whose run steps past the coarse margin, is checked by the
  // next finer one.
  const bool check_pair = checks_fine_pair(*r.method, centres, r.run, coarse_side, e.value);
  if (r.outcome == Outcome::unresolved || r.run.steps < kFewSteps || check_pair)
    second_companion(r, body, how, options, o, rerun, *f, check_pair);
}

void estimate_and_settle(BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                         const Options& options, const Rerun& rerun) {
  estimate_error(r, body, centres, how, options, rerun);
  estimate_event_errors(r, body, centres, how, options, rerun);
  settle(r.outcome, r.reason, r.warnings, r.error, options.max_error, options.max_energy_error,
         final_energy_error(body, centres, r.run.final));
}

}  // namespace bodypoint::detail

namespace bodypoint {

double ErrorEstimate::quantity(double x_run, double x_companion, double rounding) const {
  if (!pair || !known()) return std::numeric_limits<double>::quiet_NaN();
  const double apart = state_distance(pair->run, pair->companion);
  if (!(apart > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return std::max(kQuantityMargin * value / apart * std::abs(x_run - x_companion), rounding);
}

}  // namespace bodypoint
