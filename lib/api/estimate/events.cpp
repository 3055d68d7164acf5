// bodypoint: the errors of a run's located events (estimate.hpp, estimate_event_errors). Companions at 2h and 4h
// locate the same events; in the asymptotic regime every smooth quantity of a run (an event's time, its distance,
// its state) errs by the same multiple of what the pair differs by in it, so a quantity whose three values fall as
// an order gets Richardson's error at that order, at least the final state's estimate over its pair's difference;
// a time whose values observe no order gets the bound its state's error gives (time_error_from_state).
#include "parts.hpp"

#include "events.hpp"

#include "bodypoint/accuracy.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace bodypoint::detail {
namespace {

/// The events' companion runs at this multiple of the run's step (half a run; far-ip and KS, without an
/// order, at 1/kFinerRatio of theirs, as their searches pair them).
constexpr double kEventRatio = 2.0;
constexpr double kFinerRatio = 1.25;
/// A pair that locates an event at the same double has still erred by its rounding: the errors are at least
/// this relative part of the time and distance (a few units in the last place, the rounding probes' start
/// shift), and the state's at least the run's own estimate's share of it.
constexpr double kEventRounding = bodypoint::kStartShift;
constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();

/// The step of the run r asked as `how`: the accuracy mode's delivered one, or the step by which it ran.
struct RunStep {
  double h = 0.0, t_end = 0.0, omega_c = -1.0;
  const MethodInfo* method = nullptr;
};

std::optional<RunStep> run_step(const BodyResult& r, const Advance& how, const Options& options) {
  RunStep s;
  s.omega_c = options.omega_c;
  s.method = r.method;
  if (const auto* a = std::get_if<Accuracy>(&how); a && r.accuracy) {
    s = RunStep{r.accuracy->h_chosen, a->t_end, r.accuracy->omega_c, r.method};
  } else if (const auto* f = std::get_if<FixedSteps>(&how)) {
    s.h = f->h;
    s.t_end = f->h * static_cast<double>(f->steps);
  } else if (const auto* x = std::get_if<FictitiousSteps>(&how); x && x->end.index() == 0) {
    s = RunStep{x->ds, x->t_end(), options.omega_c, r.method};
  } else {
    return std::nullopt;  // a controlled step, a counted number of fictitious steps
  }
  return s.h > 0.0 && s.t_end > 0.0 ? std::optional<RunStep>(s) : std::nullopt;
}

/// The companion's way of advancing: `ratio` times the step (fixed steps landing on the same end).
Advance scaled(const RunStep& s, double ratio) {
  return advance_of(*s.method, {.step = ratio * s.h, .end = s.t_end});
}

/// The k-th hit of each event in `hits`, by (event, k).
std::map<std::pair<std::size_t, int>, const EventHit*> by_occurrence(const std::vector<EventHit>& hits) {
  std::map<std::pair<std::size_t, int>, const EventHit*> out;
  std::map<std::size_t, int> seen;
  for (const EventHit& h : hits) out[{h.event, seen[h.event]++}] = &h;
  return out;
}

/// A hit's quantities that get an error: its time, its distance, its state (relative).
std::array<double, 3> differences(const EventHit& a, const EventHit& b) {
  return {std::abs(a.t - b.t), std::abs(a.r - b.r), bodypoint::state_distance(a.s, b.s)};
}

/// The hits of `x` paired with r's by occurrence; none where an event is hit another number of times.
std::vector<const EventHit*> partners(const std::vector<EventHit>& ours, const std::vector<EventHit>& theirs) {
  std::map<std::size_t, int> mine, other;
  for (const EventHit& h : ours) ++mine[h.event];
  for (const EventHit& h : theirs) ++other[h.event];
  const auto found = by_occurrence(theirs);
  std::vector<const EventHit*> out;
  std::map<std::size_t, int> k;
  for (const EventHit& h : ours) {
    const auto it = found.find({h.event, k[h.event]++});
    out.push_back(it == found.end() || mine[h.event] != other[h.event] ? nullptr : it->second);
  }
  return out;
}

/// Differences at or below this relative size are the runs' rounding (the search's kRoundOff): taken whole.
constexpr double kRoundingBand = 1e-13;
/// A quantity's differences d1 (the run against 2h) and d2 (2h against 4h) observe the order log2(d2/d1);
/// its error is Richardson's from d1 at the lower of that and p, trusted where the observed order lies in
/// [kLeastOrder, p + kOrderAbove] (as the estimate of the final state takes min(q, p): a pair whose terms
/// cancel near 2h falls faster than its order once and reads a fraction of the error). Rounding-level
/// differences are the error whole. NaN: not known.
constexpr double kLeastOrder = 1.0, kOrderAbove = 2.0;
double quantity_error(double d1, double d2, int p, double scale, double final_factor) {
  if (d1 <= kRoundingBand * scale && d2 <= kRoundingBand * scale) return std::max({d1, d2, kEventRounding * scale});
  if (!(d1 > 0.0 && d2 > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double q = std::log2(d2 / d1);
  if (q < kLeastOrder || q > p + kOrderAbove) return std::numeric_limits<double>::quiet_NaN();
  const double richardson = 1.0 / (std::pow(kEventRatio, std::min<double>(q, p)) - 1.0);
  return std::max(d1 * std::max(richardson, final_factor), kEventRounding * scale);
}

/// Where an event time's differences observe no order (the closest approach on table 3.1 under --tol 1e-8: the
/// times at h and 2h 8.6e-11 and 1.1e-10 off, 4h's out of its regime, -3.6e-8), its error from the state's: a state off by
/// `state_error` (relative in R and in v, the tool's norm) moves the root of g by at most what g changes by over
/// g's rate along the motion. For the events whose g reads R and v alone (closest, local minimum, radius, plane);
/// NaN for departure and arrival, whose guiding centre reads the spin, which the norm does not bound.
double time_error_from_state(const Event& e, const BodyPoint& p, const std::vector<Centre>& centres, const State& s,
                             double state_error) {
  using K = Event::Kind;
  const double dR = state_error * s.R.norm(), dv = state_error * s.v.norm();
  double dg = kUnknown;  // at most |grad_R g| dR + |grad_v g| dv
  switch (e.kind) {
    case K::closest_approach:
    case K::local_minimum: dg = s.v.norm() * dR + (s.R - centres[e.centre].c).norm() * dv; break;  // g = (R - c).v
    case K::radius: dg = dR; break;                                                                  // g = |R - c| - r
    case K::plane: dg = e.normal.norm() * dR; break;                                                 // g = n.R - offset
    case K::departure:
    case K::arrival: break;
  }
  const double dt = std::abs(dg / event_rate(e, p, centres, s));
  return std::isfinite(dt) ? dt : kUnknown;
}

/// The errors the three runs left unknown, from the state's where it is known: a stop event's state is the run's
/// final state, whose estimate is `final_error`; the time from time_error_from_state; the distance at a time
/// t_error off from a position state_error off, what it moves by either way.
void bound_from_state(EventHit& h, const Event& e, const BodyPoint& p, const std::vector<Centre>& centres, double final_error) {
  if (std::isnan(h.state_error)) h.state_error = final_error;
  if (!std::isfinite(h.state_error)) return;
  if (std::isnan(h.t_error))
    h.t_error = std::max(time_error_from_state(e, p, centres, h.s, h.state_error), kEventRounding * std::abs(h.t));
  if (std::isnan(h.r_error) && std::isfinite(h.t_error) && !e.about && !centres.empty()) {
    const Vec3 d = h.s.R - centres[e.kind == Event::Kind::plane ? 0 : e.centre].c;
    h.r_error = std::max(h.state_error * h.s.R.norm() + std::abs(d.dot(h.s.v)) / d.norm() * h.t_error, kEventRounding * h.r);
  }
}

}  // namespace

void estimate_event_errors(BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                           const Options& options, const Rerun& rerun) {
  if (r.events.empty() || !options.estimate_events || !r.method || !ran(r.outcome) || !r.error.known()) return;
  const std::optional<RunStep> step = run_step(r, how, options);
  if (!step) return;
  const int p = effective_order(*r.method, body);
  // A companion as the estimate's (companion_options) that locates every event and tracks no invariant, with the
  // constant c the run had (the accuracy mode's delivered one).
  Options o = companion_options(body, centres, how, options);
  o.events = options.events;
  o.track_invariants = false;
  if (step->omega_c >= 0.0) o.omega_c = step->omega_c;
  // Order p: companions at 2h and 4h (three quarters of a run), a quantity's error trusted where the three
  // fall as order p. Without an order (far-ip, KS): one at h/1.25, as their searches pair them.
  const BodyResult x = rerun(body, scaled(*step, p > 0 ? kEventRatio : 1.0 / kFinerRatio), o);
  r.event_force_evals += x.total_force_evals();
  if (!ran(x.outcome) || !is_finite(x.run.final)) return;
  std::optional<BodyResult> y;
  if (p > 0) {
    y = rerun(body, scaled(*step, kEventRatio * kEventRatio), o);
    r.event_force_evals += y->total_force_evals();
    if (!ran(y->outcome)) return;
  }
  // What the final state's estimate makes of the pair's difference there: its margins, carried to the events
  // (in the asymptotic regime every smooth quantity errs by the same multiple). Not where the final pair differs
  // at the rounding level: there the estimate is its rounding draws', which say nothing of an earlier event's
  // truncation (lp-y4 h = 0.01 to t = 40: r_min stated 60x its error).
  const double apart = bodypoint::state_distance(r.run.final, x.run.final);
  const double final_factor = apart > kRoundingLevel ? r.error.value / apart : 0.0;
  const std::vector<const EventHit*> with_x = partners(r.events, x.events);
  const std::vector<const EventHit*> with_y = y ? partners(r.events, y->events) : std::vector<const EventHit*>(r.events.size());
  const bool stopped_here = stopped_by_event(r, options);
  for (std::size_t i = 0; i < r.events.size(); ++i) {
    EventHit& h = r.events[i];
    if (!with_x[i] || (y && !with_y[i])) continue;  // no partner: its errors are not known
    const std::array<double, 3> d1 = differences(h, *with_x[i]);
    const std::array<double, 3> scale{std::abs(h.t), h.r, 1.0};
    std::array<double*, 3> out{&h.t_error, &h.r_error, &h.state_error};
    for (std::size_t q = 0; q < 3; ++q)
      *out[q] = y ? quantity_error(d1[q], differences(*with_x[i], *with_y[i])[q], p, scale[q], final_factor)
                  : std::max(d1[q] * std::max(1.0, final_factor), kEventRounding * scale[q]);
    bound_from_state(h, options.events[h.event], body.p, centres, stopped_here && i + 1 == r.events.size() ? r.error.value : kUnknown);
  }
}

}  // namespace bodypoint::detail
