// bodypoint: an encounter whose far field is crossed by legs of one turn of the spin a step
// (splitting/far_turn.hpp; docs/physics.md, "The far field by one turn a step").
//
// A spinning body that starts far from the centres crosses, in auto's run, a far field whose steps are
// capped by the spin: the cost grows like the start distance L. Where the encounter allows it, the run
// is three: a far leg from the start to the hand-off distance r_h, auto's run from there to its
// departure through r_h (its search, estimate and events as always), and a far leg out to the start
// distance. Each leg is run at two steps; the finer is delivered, and its error is what the two differ
// by plus a share of the quiver corrections it made (the averaged model's error). The legs land on
// half the start distance on the way (the asymptotes' error estimate reads the states there).
#include "bodypoint/bodypoint.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/scattering.hpp"
#include "bodypoint/splitting/catalogue.hpp"
#include "bodypoint/splitting/far_turn.hpp"
#include "checked.hpp"
#include "encounter_parts.hpp"
#include "events.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace bodypoint::detail {
namespace {

namespace sp = splitting;

/// A leg's steps are this share of r/|v| (its companion's, the one delivered, half of it). Its error is the averaged
/// model's more than the step's: Kahan-Li 6 with a turn for each kick errs 1.9e-9 at eta 0.1 from L = 3200 to
/// r = 400 on table 3.1, 2.5e-9 at 0.2 (bench/far_turn); at 0.4 the helix's phase 6e-8 (the guiding centre's orbit
/// 1.6e-9), which the pair's difference states. The pair at 0.4 and 0.2 costs half the pair at 0.2 and 0.1, and
/// its encounters stay within their errors (docs/measurements.md, "Legs at eta 0.4 and 0.2"): at the limit from
/// L = 12,800 on 32 made-up scenes at TOL 1e-6 .. 1e-8 against references at 1e-10, the deflection, time delay and
/// out-of-plane angle at most 0.6 of their stated errors, the closest approach's distance 0.36 and time 0.17; table
/// 3.1 from 12,800 at 1e-6 costs 21,208 evaluations (26,152 at 0.2; 23,604 from L = 200).
constexpr double kLegEta = 0.4;
/// The leg's model error against its quiver corrections' size in the state, on the scenes of
/// bench/far_turn.cpp (docs/measurements.md, "An encounter at infinity"): at most 1/86 of it; a bound about
/// twice that. A leg going out is off in the outgoing asymptote's direction by this share of its
/// correction's effect on it too.
constexpr double kModelShare = 1.0 / 50.0;
/// Across K1 the averaged model leaves the guiding centre off by up to 2.1 times what the quiver correction
/// moved it, and by up to 1.14 times the quiver's size |A| rho/(r^2 |K1| Omega) (Omega = |B| |K1|/D): 0.32 ..
/// 2.1 and 0.2 .. 1.14 on bench/far_turn.cpp's scenes (b = 0.3 .. 10, B = 0.3 .. 0.9, r = 200 .. 800; it
/// moves with the step's phases: b = 1 at r = 400 and 403, 7.1e-8 and 3.2e-7). A leg coming in is taken to
/// be off in the incoming asymptote by this many times its correction's effect on it, and the hand-off is
/// planned for kAcrossQuiver times the quiver's size.
constexpr double kAcrossModelShare = 3.0;
constexpr double kAcrossQuiver = 1.5;
/// Along the path the averaged model leaves a leg coming in off in the time delay (its time less its
/// asymptotic motion's, read at its end) by up to 1.84 times what its quiver correction moved the delay: 0.001
/// .. 1.84 (median 0.24) over 60 encounters with legs from L = 3200 and 12,800 at TOL 1e-6 .. 1e-8 against the
/// same starts by logh-kl6 or ttl-kl6 at 1e-9 (eleven scenes; 1.84 on Kx = 4, A = -1 at 1e-8, r_h 580). The
/// state's 1/86 (kModelShare) does not hold here: 1/50 had stated 2.8e-8 for a delay 4.9e-8 off. Taken 3x, as
/// across K1.
constexpr double kDelayModelShare = 3.0;
/// A leg coming in moves the incoming asymptote's impact parameter b, which the encounter turns into the
/// deflection by dtheta/db, Rutherford's 2a/(a^2 + b^2) (a = |A|/(|K1| v), sin(theta)/b) for a point mass;
/// this many times that (b = 1 on table 3.1: 3.2e-7 across moved the deflection by 2.2e-8, 0.069 of it, where
/// sin(theta)/b is 0.090).
constexpr double kSensitivity = 1.5;
/// The share of TOL the legs' orbit may take; auto's run between them is asked for the rest.
constexpr double kLegShare = 0.5;
/// The hand-off is at least this many turns of the spin while the body crosses it (the leg's
/// own bound is splitting::kMinTurns; the model's error grows faster than 1/r^2 below about 100 on
/// table 3.1, 15 turns at r = 136) ...
constexpr double kHandOffTurns = 15.0;
/// ... and this many times the encounter's own scale (its straight path's distance from the centre, or
/// the distance where the potential is the kinetic energy).
constexpr double kHandOffScale = 8.0;
/// Legs are used where the start is at least this far beyond the hand-off: nearer, the run from the
/// start costs little more than the legs and their companions.
constexpr double kLegGain = 2.0;

struct Plan {
  double r0 = 0.0;       ///< the start distance of the guiding centre from `about`
  double r_hand = 0.0;   ///< where auto's run takes over, and hands back
  Vec3 about = Vec3::Zero();
  std::size_t arrival = 0, departure = 0, stop = 0;  ///< their indices in the events
};

/// The index of the event (kind, value, stop), or -1.
long find_event(const std::vector<Event>& events, Event::Kind kind, double value, bool stop) {
  for (std::size_t i = 0; i < events.size(); ++i)
    if (events[i].kind == kind && events[i].value == value && events[i].stop == stop) return static_cast<long>(i);
  return -1;
}

/// Whether this run is an encounter to its departure that legs can serve, and where they hand off.
std::optional<Plan> plan_legs(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                              const Advance& how, const Options& options) {
  const auto* a = std::get_if<Accuracy>(&how);
  if (method || !a || options.sink || body.p.B == 0.0 || !(a->t_end > 0.0)) return std::nullopt;
  for (const Centre& c : centres)
    if (c.law != ForceLaw::coulomb) return std::nullopt;
  const std::optional<Centre> far = far_field_centre(centres);
  if (!far || far->A == 0.0) return std::nullopt;
  Plan plan;
  plan.about = far->c;
  const Vec3 from = guiding_centre(body.p, body.s0) - plan.about;  // the guiding centre from the far-field centre
  plan.r0 = from.norm();
  const double half = 0.5 * plan.r0;
  const long arrival = find_event(options.events, Event::Kind::arrival, half, false);
  const long departure = find_event(options.events, Event::Kind::departure, half, false);
  const long stop = find_event(options.events, Event::Kind::departure, 0.0, true);
  if (arrival < 0 || departure < 0 || stop < 0) return std::nullopt;
  // The encounter's own events and nothing else (a caller's radius, plane or arrival has no leg to fall on).
  for (std::size_t i = 0; i < options.events.size(); ++i) {
    const Event& e = options.events[i];
    const bool own = e.kind == Event::Kind::closest_approach ? !e.stop
                                                              : static_cast<long>(i) == arrival ||
                                                                    static_cast<long>(i) == departure || static_cast<long>(i) == stop;
    if (!own) return std::nullopt;
  }
  plan.arrival = static_cast<std::size_t>(arrival);
  plan.departure = static_cast<std::size_t>(departure);
  plan.stop = static_cast<std::size_t>(stop);
  // The hand-off: the turns, the encounter's scale, and the model's error in the deflection within its share
  // of TOL: an offset across K1 of kAcrossQuiver the quiver's size |A| rho/(r^2 |K1| Omega), turned into the
  // deflection by kSensitivity dtheta/db (Rutherford's, from the straight path's distance). The turns take
  // the body's speed at any orientation of its spin far out, (J |K1| + |B| |K2|)/D (a back-scattered body
  // leaves faster than it came: K1 turns against K2).
  const Momenta q = to_momenta(body.p, body.s0);
  const double K1 = q.K1.norm(), v = (body.p.J * K1 + std::abs(body.p.B) * q.K2.norm()) / body.p.D();
  if (!(K1 > 0.0) || !(body.s0.v.norm() > 0.0)) return std::nullopt;
  const Vec3 u = q.K1 / K1;
  if (from.dot(u) >= 0.0) return std::nullopt;  // not coming in
  const double rho = q.K2.cross(u).norm() / K1;
  const double period = 2.0 * M_PI * body.p.D() / (std::abs(body.p.B) * K1);
  const double line = from.cross(u).norm();
  const double speed = body.s0.v.norm();  // the model's and the encounter's scales take the speed it has
  const double coulomb = 2.0 * std::abs(far->A) / (K1 * speed);
  const double ruth = std::abs(far->A) / (K1 * speed), per_b = kSensitivity * 2.0 * ruth / (ruth * ruth + line * line);
  const double omega = std::abs(body.p.B) * K1 / body.p.D();
  const double model = std::sqrt(kAcrossQuiver * per_b * std::abs(far->A) * rho / (K1 * omega * 0.5 * kLegShare * a->tol));
  plan.r_hand = std::max({kHandOffTurns * period * v, kHandOffScale * std::max(line, coulomb), model});
  if (plan.r0 < kLegGain * plan.r_hand) return std::nullopt;
  return plan;
}

/// One leg at kLegEta and at half of it: the finer's state, and its error.
struct Leg {
  State end, coarse, averaged;  ///< the finer run's end, the coarser's, the finer's before its quiver correction
  std::string refused;  ///< FarLeg::refused of either run
  double t = 0.0, t_coarse = 0.0, error = 0.0;  ///< the finer run's time to its stop, the coarser's
  double quiver = 0.0;  ///< the finer run's FarLeg::quiver
  long steps = 0, evals = 0;
};
Leg leg(const Body& body, const std::vector<Centre>& centres, const State& start, const sp::LegStop& stop) {
  Leg out;
  for (const double eta : {kLegEta, 0.5 * kLegEta}) {
    sp::FarTurnKernel<CentreList> k(body.p, CentreList{centres});
    sp::LieState x = k.initial_state(start);
    const sp::FarLeg l = sp::far_leg<sp::ops_of<sp::KahanLi6>>(k, x, std::numeric_limits<double>::infinity(), eta, stop);
    out.evals += k.evals();
    out.end = k.to_physical(x);
    if (!l.refused.empty()) {
      out.refused = l.refused;
      return out;
    }
    if (eta == kLegEta) {
      out.coarse = out.end;
      out.t_coarse = l.t;
      continue;
    }
    out.t = l.t;
    out.steps = l.steps;
    out.averaged = l.averaged_end;
    out.quiver = l.quiver;
    out.error = state_distance(out.coarse, out.end) + kModelShare * l.quiver;
  }
  return out;
}

EventHit hit_at(std::size_t event, double t, const State& s, const Vec3& centre) {
  EventHit h;
  h.event = event;
  h.t = t;
  h.s = s;
  h.r = (s.R - centre).norm();
  return h;
}

/// The four legs of an encounter: in to half the start distance and on to the hand-off, out to half the
/// start distance and on to the start distance.
struct Legs {
  Leg in_half, in, out_half, out;
  /// The encounter from 2L beside one from L (run_pair_with_legs) goes out on the other's legs to L (`out_half`
  /// and `out`, the other's: its half distance is at their end) and on from there to 2L.
  std::optional<Leg> beyond;
  [[nodiscard]] long evals() const {
    return in_half.evals + in.evals + out_half.evals + out.evals + (beyond ? beyond->evals : 0);
  }
  [[nodiscard]] long steps_out() const { return out_half.steps + out.steps + (beyond ? beyond->steps : 0); }
  /// The legs going out, each with the state it starts from (`near_end`: the end of auto's run between them).
  [[nodiscard]] std::vector<std::pair<const Leg*, const State*>> outs(const State& near_end) const {
    std::vector<std::pair<const Leg*, const State*>> o{{&out_half, &near_end}, {&out, &out_half.end}};
    if (beyond) o.emplace_back(&*beyond, &out.end);
    return o;
  }
  [[nodiscard]] const Leg& last() const { return beyond ? *beyond : out; }
  /// The leg going out that ends at the encounter's half distance (the departure's hit).
  [[nodiscard]] const Leg& at_half() const { return beyond ? out : out_half; }
};

/// The guiding centre's offset across K1 between the states x and y (K1 of x): what moves the path (b read from
/// K2Q does not see it: every sub-flow, the quiver's turn included, keeps K2Q).
double offset_across_K1(const BodyPoint& p, const State& x, const State& y) {
  const Vec3 u = to_momenta(p, x).K1.normalized();
  return (guiding_centre(p, x) - guiding_centre(p, y)).cross(u).norm();
}

/// The distance of the guiding centre's straight path in the state `s` (along K1) from `about`: what moves an
/// encounter's path between two states at the same distance from the centre (an offset across K1 that a
/// rotation about the centre makes leaves it).
double line_distance(const BodyPoint& p, const State& s, const Vec3& about) {
  return (guiding_centre(p, s) - about).cross(to_momenta(p, s).K1.normalized()).norm();
}

/// What the legs' errors make of the deflection (rad). A leg going out moves the outgoing asymptote: the
/// deflection from the start to its end against to its coarser run's end, and kModelShare of that to its end
/// before the quiver correction (the averaged model's error). A leg coming in moves the incoming asymptote:
/// the same differences of the deflection from its end to the end of auto's run `near_end`, and of the guiding
/// centre's offset across K1 (the impact parameter's) turned into the deflection by kSensitivity sin(theta)/b,
/// the model's kAcrossModelShare times its correction's.
double deflection_error(const Body& body, const std::vector<Centre>& centres, const Legs& g, const State& near_end) {
  const auto in_of = [&](const State& s) { return scattering(body.p, centres, s, near_end); };
  const Scattering at = in_of(g.in.end);
  const double per_b = kSensitivity * std::abs(std::sin(at.deflection)) / at.b;
  const auto in_part = [&](const Leg& l, const State& other) {
    return std::abs(in_of(l.end).deflection - in_of(other).deflection) + per_b * offset_across_K1(body.p, l.end, other);
  };
  const auto out_part = [&](const Leg& l, const State& other) {
    return std::abs(scattering(body.p, centres, body.s0, l.end).deflection -
                    scattering(body.p, centres, body.s0, other).deflection);
  };
  double e = 0.0;
  for (const Leg* l : {&g.in_half, &g.in}) e += in_part(*l, l->coarse) + kAcrossModelShare * in_part(*l, l->averaged);
  for (const auto& [l, from] : g.outs(near_end)) e += out_part(*l, l->coarse) + kModelShare * out_part(*l, l->averaged);
  return std::isfinite(e) ? e : std::numeric_limits<double>::quiet_NaN();
}

/// What the legs' errors and the run between them, `r` from the state `near` (its estimate's pair), make of
/// the time delay: each leg's delay (its time less its asymptotic motion's, read through the asymptote at its
/// end) at its end against its coarser run's and, times the model's share (kDelayModelShare coming in,
/// kModelShare going out), its end before the quiver correction; a leg coming in moves the impact parameter
/// too, which the encounter turns into the delay by kSensitivity |dT/db| = sin(theta)/v_inf for a point mass
/// (Rutherford's); the run's part as any run's (time_delay_run_error, its pair read from `near`).
double delay_error(const Body& body, const std::vector<Centre>& centres, const Legs& g, const Body& near,
                   const BodyResult& r) {
  const State& near_end = r.run.final;
  const auto T = [&](const State& from, const State& to, double t) { return scattering(body.p, centres, from, to, t).time_delay; };
  const Scattering at = scattering(body.p, centres, g.in.end, near_end, r.run.t_end);
  const double per_b = kSensitivity * std::abs(std::sin(at.deflection)) / at.v_inf;
  // A leg coming in: the delay from its end to the near run's end, its own time added (along its path), and
  // what its offset across K1 makes of the delay.
  const auto along = [&](const Leg& l, const State& other, double t_other) {
    return std::abs(l.t + T(l.end, near_end, r.run.t_end) - t_other - T(other, near_end, r.run.t_end));
  };
  // A leg going out from `from`: the delay from there to its end.
  const auto out_part = [&](const Leg& l, const State& from, const State& other, double t_other) {
    return std::abs(T(from, l.end, l.t) - T(from, other, t_other));
  };
  double e = 0.0;
  for (const Leg* l : {&g.in_half, &g.in})
    e += along(*l, l->coarse, l->t_coarse) + per_b * offset_across_K1(body.p, l->end, l->coarse) +
         kDelayModelShare * along(*l, l->averaged, l->t) + kAcrossModelShare * per_b * offset_across_K1(body.p, l->end, l->averaged);
  for (const auto& [l, from] : g.outs(near_end))
    e += out_part(*l, *from, l->coarse, l->t_coarse) + kModelShare * out_part(*l, *from, l->averaged, l->t);
  e += time_delay_run_error(near, centres, r.error, r.run.t_end);
  return std::isfinite(e) ? e : std::numeric_limits<double>::quiet_NaN();
}

/// What the legs coming in make of a closest approach that the run between them passes at its time `t` (from the
/// hand-off): of its distance and of its time from the start.
struct Approach {
  double r = 0.0, t = 0.0;
};
/// The shares of a leg's differences taken: its coarser run's whole; of the quiver correction's effect, the
/// averaged model's across K1 (the impact parameter), in the state (the helix and the speed) and along the path.
struct Shares {
  double across = 1.0, state = 1.0, along = 1.0;
};
/// Each leg's end against its coarser run's end and, at the model's shares (kAcrossModelShare, kModelShare,
/// kDelayModelShare), against its end before the quiver correction. The incoming asymptote's impact parameter moved
/// by db and its speed by dv (relative) move a point mass's periapsis sqrt(a^2 + b^2) +- a (a = |A|/(|K1| v)) by at
/// most db + 4 a dv (Rutherford's, taken kSensitivity times as for the deflection); the helix about the guiding
/// centre adds what its vector differs by at the leg's end and the turn that dv makes of the spin's rate
/// (|B| |K1|/D) until `t`. The time: the legs' own times, the guiding centre's offset along K1 over the speed, and
/// dv of the time until `t`.
Approach approach_error(const Body& body, const std::vector<Centre>& centres, const Legs& g, const State& near_end, double t) {
  const auto in_of = [&](const State& s) { return scattering(body.p, centres, s, near_end); };
  const Momenta q = to_momenta(body.p, g.in.end);
  const std::optional<Centre> far = far_field_centre(centres);
  const double K1 = q.K1.norm(), v = in_of(g.in.end).v_inf;
  const double a = far ? std::abs(far->A) / (K1 * v) : std::numeric_limits<double>::quiet_NaN();
  const double spin_rate = std::abs(body.p.B) * K1 / body.p.D();
  const Vec3 u = q.K1 / K1;
  const auto helix = [&](const State& s) -> Vec3 { return s.R - guiding_centre(body.p, s); };
  const double rho = helix(g.in.end).norm();
  Approach e;
  const auto add = [&](const Leg& l, const State& other, double t_other, const Shares& k, double until) {
    const Scattering here = in_of(l.end), there = in_of(other);
    const double dv = std::abs(here.v_inf - there.v_inf) / v, db = std::abs(here.b - there.b);
    const double along = std::abs((guiding_centre(body.p, l.end) - guiding_centre(body.p, other)).dot(u));
    e.r += kSensitivity * (k.across * db + k.state * 4.0 * a * dv) +
           k.state * ((helix(l.end) - helix(other)).norm() + rho * spin_rate * until * dv);
    e.t += std::abs(l.t - t_other) + k.along * along / v + k.state * until * dv;
  };
  for (const Leg* l : {&g.in_half, &g.in}) {
    const double until = t + (l == &g.in_half ? g.in.t : 0.0);
    add(*l, l->coarse, l->t_coarse, Shares{}, until);
    add(*l, l->averaged, l->t, Shares{kAcrossModelShare, kModelShare, kDelayModelShare}, until);
  }
  if (!std::isfinite(e.r)) e.r = std::numeric_limits<double>::quiet_NaN();
  if (!std::isfinite(e.t)) e.t = std::numeric_limits<double>::quiet_NaN();
  return e;
}

/// `evals` spent for `r` beyond its run: in its count and, where the accuracy mode ran it, in the search's, which
/// the total reads (BodyResult::total_force_evals).
void count(BodyResult& r, long evals) {
  r.run.force_evals += evals;
  if (r.accuracy) r.accuracy->force_evals += evals;
}

/// auto's run `r` between the legs made the run of the whole encounter: its hits on the encounter's own
/// events (the near run's closest approaches, the half distance's, the end), its time, cost and errors.
void join(BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Legs& g, const Plan& plan,
          const Options& options, const Body& near, const Options& near_options, double tol) {
  const Vec3& centre = centres[options.events[plan.arrival].centre].c;
  const double t_in = g.in_half.t + g.in.t;
  std::vector<EventHit> hits{hit_at(plan.arrival, g.in_half.t, g.in_half.end, centre)};
  for (EventHit h : r.events) {
    const Event& e = near_options.events[h.event];
    if (e.kind != Event::Kind::closest_approach) continue;
    for (std::size_t k = 0; k < options.events.size(); ++k)
      if (options.events[k].kind == e.kind && options.events[k].centre == e.centre) h.event = k;
    // Located on the run between the legs, from a hand-off that carries the legs' errors (NaN stays: the location's
    // error not known; their part of the distance's is kept for the limit, closest_from_limit).
    const Approach legs = approach_error(body, centres, g, r.run.final, h.t);
    h.r_error += legs.r;
    h.t_error += legs.t;
    h.state_error += g.in_half.error + g.in.error;
    double& kept = r.error.closest_from_legs;  // the largest; not known (NaN) where any is not
    kept = std::isnan(kept) || std::isnan(legs.r) ? std::numeric_limits<double>::quiet_NaN() : std::max(kept, legs.r);
    h.t += t_in;
    hits.push_back(h);
  }
  double t = t_in + r.run.t_end, error = g.in_half.error + g.in.error;
  for (const auto& [l, from] : g.outs(r.run.final)) {
    t += l->t;
    error += l->error;
    if (l == &g.at_half()) hits.push_back(hit_at(plan.departure, t, l->end, centre));
  }
  const double t_end = t;
  hits.push_back(hit_at(plan.stop, t_end, g.last().end, centre));
  const double orbit = deflection_error(body, centres, g, r.run.final);
  r.error.time_delay = delay_error(body, centres, g, near, r);
  r.error.pair.reset();  // the run's, from the hand-off: the encounter's delay is read from time_delay
  r.events = std::move(hits);
  r.run.final = g.last().end;
  r.run.t_end = t_end;
  r.run.steps += g.in_half.steps + g.in.steps + g.steps_out();
  count(r, g.evals());
  r.error.orbit = r.error.value + orbit;
  r.error.value += error;
  if (r.accuracy) r.accuracy->err_estimate = r.error.value;
  const std::string legs = "far legs of one turn of the spin a step beyond r = " + fmt(plan.r_hand) + " (" +
                           std::to_string(g.in_half.steps + g.in.steps) + " steps in, " +
                           std::to_string(g.steps_out()) + " out, " + std::to_string(g.evals()) +
                           " force evaluations with their companions, estimated error " + fmt(error) + ", in the deflection " +
                           fmt(orbit) + "; the invariants are the run's between them)";
  r.error.basis += "; " + legs;
  r.chosen += r.chosen.empty() ? legs : "; " + legs;
  if (r.error.value > tol)
    r.warnings.push_back("the final state's error " + fmt(r.error.value) + " is above tol " + fmt(tol) +
                         ": the far legs know the helix's phase along the path less well than the orbit, which the "
                         "encounter's observables read (their error in the deflection with the run's " + fmt(r.error.orbit) +
                         "); a state at tol wants a named method");
}

/// The legs of `body` in to the hand-off: to half its start distance and on to r_hand; false where one stops short.
bool in_legs(Legs& g, const Body& body, const std::vector<Centre>& centres, const Plan& plan) {
  g.in_half = leg(body, centres, body.s0, {plan.about, 0.5 * plan.r0, false});
  if (g.in_half.refused.empty()) g.in = leg(body, centres, g.in_half.end, {plan.about, plan.r_hand, false});
  return g.in_half.refused.empty() && g.in.refused.empty();
}

/// The legs of `body` out from `from`, the end of the run between the legs: to half its start distance and on
/// to it; false where one stops short.
bool out_legs(Legs& g, const Body& body, const std::vector<Centre>& centres, const State& from, const Plan& plan) {
  g.out_half = leg(body, centres, from, {plan.about, 0.5 * plan.r0, true});
  if (g.out_half.refused.empty()) g.out = leg(body, centres, g.out_half.end, {plan.about, plan.r0, true});
  return g.out_half.refused.empty() && g.out.refused.empty();
}

/// auto's run between the legs: from the hand-off state `at` of `body` to its departure through there, at the
/// share of TOL the legs leave, with the encounter's events from there.
struct Near {
  Body body;
  Options options;
  BodyResult r;
  [[nodiscard]] bool finished() const { return r.outcome == Outcome::ok && r.run.stopped; }
};
Near near_run(const Body& body, const State& at, const std::vector<Centre>& centres, const Accuracy& a, const Options& options) {
  Near n{Body{body.p, at, body.name}, options, {}};
  n.options.events.clear();
  n.options = encounter_options(n.body, centres, n.options, true);
  n.r = integrate_checked(n.body, centres, nullptr,
                          Accuracy{(1.0 - kLegShare) * a.tol, encounter_span(n.body, centres), 0.0, a.first_step, a.first_step_of},
                          n.options);
  return n;
}

/// auto's run of `body` without legs, where a leg stopped short: `spent` counted in it.
BodyResult without_legs(const Body& body, const std::vector<Centre>& centres, const Accuracy& a, const Options& options,
                        long spent) {
  BodyResult plain = integrate_checked(body, centres, nullptr, a, options);
  count(plain, spent);
  return plain;
}

/// The run of `plan`: the legs and auto's run between them, as one run of the whole encounter. Where a leg
/// stops short (far_leg's reasons) the encounter is auto's run without legs, the legs' work counted in it.
BodyResult run_with_legs(const Body& body, const std::vector<Centre>& centres, const Accuracy& a, const Options& options,
                         const Plan& plan) {
  Legs g;
  if (!in_legs(g, body, centres, plan)) return without_legs(body, centres, a, options, g.evals());
  Near n = near_run(body, g.in.end, centres, a, options);
  if (!n.finished()) {  // refused, failed or unfinished: said at its own times
    count(n.r, g.evals());
    return n.r;
  }
  if (!out_legs(g, body, centres, n.r.run.final, plan))
    return without_legs(body, centres, a, options, g.evals() + n.r.total_force_evals());
  join(n.r, body, centres, g, plan, options, n.body, n.options, a.tol);
  return n.r;
}

/// The hand-off at the limit L -> infinity from the legs in from L (`from_L`) and from 2L (`from_2L`), landed on
/// the same distance: Richardson's 2 S(2L) - S(L) of each of their states (a scene given by asymptotic data
/// reaches a fixed distance in a state that converges as 1/L in its start distance, as its observables do), its
/// model's share from the larger of their quiver corrections; its time, steps and cost are `own`'s (the leg of
/// the encounter it hands off, whose time delay reads its time).
Leg at_limit(const Leg& from_L, const Leg& from_2L, const Leg& own) {
  const auto lim = [](const State& x, const State& y) { return State{2.0 * y.R - x.R, 2.0 * y.v - x.v, 2.0 * y.w - x.w}; };
  Leg l = own;
  l.end = lim(from_L.end, from_2L.end);
  l.coarse = lim(from_L.coarse, from_2L.coarse);
  l.averaged = lim(from_L.averaged, from_2L.averaged);
  l.quiver = std::max(from_L.quiver, from_2L.quiver);
  l.error = state_distance(l.coarse, l.end) + kModelShare * l.quiver;
  return l;
}

/// What the run between the legs `r`, from the hand-off at the limit `lim`, makes of the run from 2L's
/// observables against its own hand-off `own` (S(2L)) to first order: signed, what reading the incoming asymptote
/// at `own` instead of `lim` moves them by, the other way (the hand-offs differ by a turn about the centre, 6e-9
/// rad from L = 3200 on table 3.1, which turns the outgoing asymptote with the incoming one: the deflection with
/// the run's own incoming asymptote moves by the turn); unsigned, what a change of the straight path's distance
/// from the centre between them moves the deflection and the delay by (kSensitivity sin(theta)/b and
/// sin(theta)/v_inf, Rutherford's).
void first_order(TwiceAsFar& twice, BodyResult& r2, const BodyPoint& p, const std::vector<Centre>& centres, const Vec3& about,
                 const State& lim, const State& own, const BodyResult& r) {
  const Scattering at_lim = scattering(p, centres, lim, r.run.final, r.run.t_end);
  const Scattering at_own = scattering(p, centres, own, r.run.final, r.run.t_end);
  twice.deflection_shift = at_own.deflection - at_lim.deflection;
  twice.time_delay_shift = at_own.time_delay - at_lim.time_delay;
  twice.out_of_plane_shift = at_own.out_of_plane - at_lim.out_of_plane;
  const double line = std::abs(line_distance(p, lim, about) - line_distance(p, own, about));
  const double per = kSensitivity * std::abs(std::sin(at_lim.deflection)) * line;
  r2.error.orbit += per / at_lim.b;
  r2.error.time_delay += per / at_lim.v_inf;
}

/// The encounter of `body` from L and of `twice` from 2L (the same asymptotic data) with one run between the
/// legs, from the hand-off at the limit (at_limit): each encounter is its legs and that run, and Richardson's
/// 2 x(2L) - x(L) of their observables is the limit's as that of the two whole runs is (the run between the legs
/// answers both hand-offs' difference from the limit's to first order, 2 (S(2L) - S(L)) for the one and
/// S(2L) - S(L) for the other, which cancel in 2 x(2L) - x(L)); `twice` gets that first order's shift (first_order),
/// so that the limit's error reads the two encounters' own difference. The run from 2L carries its own legs'
/// errors and cost (the run between them and the hand-off's leg are counted once, in the run from L's, as the
/// limit carries them once). Where a leg stops short or the run between them does not finish, the run from L as
/// run_with_legs would have it (the work counted) and none from 2L.
std::pair<BodyResult, std::optional<BodyResult>> run_pair_with_legs(const Body& body, TwiceAsFar& twice,
                                                                    const std::vector<Centre>& centres, const Accuracy& a,
                                                                    const Options& options, const Plan& plan, Plan plan2) {
  plan2.r_hand = plan.r_hand;  // both land on the same distance
  Legs g, g2;
  if (!in_legs(g, body, centres, plan) || !in_legs(g2, twice.body, centres, plan2))
    return {without_legs(body, centres, a, options, g.evals() + g2.evals()), std::nullopt};
  const Leg from_L = g.in, from_2L = g2.in;
  g.in = at_limit(from_L, from_2L, from_L);
  g2.in = at_limit(from_L, from_2L, from_2L);
  Near n = near_run(body, g.in.end, centres, a, options);
  if (!n.finished()) {
    count(n.r, g.evals() + g2.evals());
    return {std::move(n.r), std::nullopt};
  }
  // The run from 2L goes out on this one's legs (their errors and cost counted here) and on to 2L.
  const auto shared = [](Leg l) {
    l.coarse = l.averaged = l.end;
    l.t_coarse = l.t;
    l.error = 0.0;
    l.evals = 0;
    return l;
  };
  if (out_legs(g, body, centres, n.r.run.final, plan)) {
    g2.out_half = shared(g.out_half);
    g2.out = shared(g.out);
    g2.beyond = leg(twice.body, centres, g.out.end, {plan2.about, plan2.r0, true});
  }
  if (!g2.beyond || !g2.beyond->refused.empty())
    return {without_legs(body, centres, a, options, g.evals() + g2.evals() + n.r.total_force_evals()), std::nullopt};
  // The run from 2L: its own legs' errors (the run between them and the hand-off's leg are the run from L's,
  // which the limit 2 x(2L) - x(L) carries once), its cost its legs'.
  BodyResult r2 = n.r;
  r2.run.force_evals = r2.event_force_evals = r2.error.force_evals = r2.run.steps = 0;
  if (r2.accuracy) r2.accuracy->force_evals = 0;
  r2.error.value = 0.0;
  r2.error.time_delay = 0.0;
  // Its leg in keeps its own time and cost; its state is the hand-off's, whose errors the run from L carries.
  g2.in.coarse = g2.in.averaged = g2.in.end;
  g2.in.error = 0.0;
  join(r2, twice.body, centres, g2, plan2, twice.options, n.body, n.options, a.tol);
  first_order(twice, r2, body.p, centres, plan.about, g.in.end, from_2L.end, n.r);
  r2.error.basis += "; the run between the legs and the hand-off's leg are the encounter's from L (its hand-off at the limit, "
                    "2 S(2L) - S(L)), their errors counted there";
  join(n.r, body, centres, g, plan, options, n.body, n.options, a.tol);
  // This run's state from the hand-off on is the limit's: it is apart from the trajectory from L by what the
  // hand-offs are, which its final state's error carries (as a leg's error, not carried through the encounter).
  const double apart = state_distance(g.in.end, from_L.end);
  n.r.error.value += apart;
  if (n.r.accuracy) n.r.accuracy->err_estimate = n.r.error.value;
  const std::string limit = "the run between the legs starts from the hand-off at the limit L -> infinity (2 S(2L) - S(L) of "
                            "the legs in from L and 2L, " + fmt(apart) + " from this start's own, in the final state's error)";
  n.r.error.basis += "; " + limit;
  n.r.chosen += "; " + limit;
  return {std::move(n.r), std::move(r2)};
}

}  // namespace

BodyResult integrate_encounter_checked(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                                       const Advance& how, const Options& options, TwiceAsFar* twice) {
  const std::optional<Plan> plan = plan_legs(body, centres, method, how, options);
  if (!plan) return integrate_checked(body, centres, method, how, options);
  const Accuracy& a = std::get<Accuracy>(how);
  if (twice) {
    const std::optional<Plan> plan2 = plan_legs(twice->body, centres, method, how, twice->options);
    if (plan2 && plan2->r0 >= kLegGain * plan->r_hand) {
      auto [at_L, at_2L] = run_pair_with_legs(body, *twice, centres, a, options, *plan, *plan2);
      twice->run = std::move(at_2L);
      return std::move(at_L);
    }
  }
  return run_with_legs(body, centres, a, options, *plan);
}

}  // namespace bodypoint::detail
