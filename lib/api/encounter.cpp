// bodypoint: an encounter measured on a run (bodypoint.hpp, Encounter; scattering.hpp).
#include "bodypoint/bodypoint.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/scattering.hpp"
#include "bodypoint/detail/model_parts.hpp"
#include "checked.hpp"
#include "choice.hpp"
#include "encounter_parts.hpp"
#include "events.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace bodypoint {
namespace {

/// A finished encounter's guiding centre is back at its start distance; the departure event locates
/// that distance to round-off in time (~1e-15 relative), and this much slack covers the located
/// state's own error without calling a body that is still inside "finished".
constexpr double kLeftSlack = 1e-9;
/// A spinning body's observables at a fixed b, v_inf and arrival phase converge as 1/L in the start
/// distance L (B = 0.7, b = 1, psi = 1: 0.0900936, 0.0901056, 0.0901116, 0.0901147 from L = 200, 400,
/// 800, 1600; docs/physics.md): x(L) - x(infinity) = 2 (x(L) - x(2L)) for the 1/L term alone, times a
/// margin of 1.5 for the next one (the differences fall by 2.0x and 1.94x there: 2 |x(200) - x(400)| is
/// 0.3 % below the limit's 2.42e-5).
constexpr double kStartDistanceFactor = 2.0 * 1.5;
/// An encounter given by asymptotic data answers at the limit L -> infinity: Richardson's 2 x(2L) - x(L)
/// removes a 1/L term, and for a single term c/L^p with p >= 0.5 it is within 1.41 |x(L) - x(2L)| of the
/// limit (0 at p = 1, 2/3 at p = 2, 1 as p grows); a margin of 1.5 on that. Table 3.1, b = 3, arrival
/// phase 1, TOL 1e-10: 0.0410657137 from L = 200 and 400, 0.0410657132 from 800 and 1600, where x(200) is 1.1e-8 away.
constexpr double kLimitFactor = 1.5;

double start_distance(const Body& body, const Centre& c) { return (detail::guiding_centre(body.p, body.s0) - c.c).norm(); }

/// The centres an encounter is measured about: the one centre, or several centres' far-field centre
/// (far_field_centre: their total charge), or each of them where there is none (a law other than Coulomb's).
std::vector<Centre> measured_about(const std::vector<Centre>& centres) {
  const std::optional<Centre> far = centres.size() > 1 ? far_field_centre(centres) : std::nullopt;
  return far ? std::vector<Centre>{*far} : centres;
}

bool has_event(const std::vector<Event>& events, Event::Kind kind, std::size_t centre, bool stop) {
  return std::any_of(events.begin(), events.end(),
                     [&](const Event& e) { return e.kind == kind && e.centre == centre && e.stop == stop; });
}

/// Why the run ended before the body left, or empty when it had left. `departed`: the run stopped at its
/// departure through the start distance, which it crossed on its own steps; the state located there is advanced
/// from the step before and may lie inside by that advance's error (an attracting scene's run from 2L by
/// ttl-pefrl at TOL 1e-6 stopped 1.7e-9 of its distance inside, and its encounter read "did not finish").
std::string unfinished(const Body& body, const std::vector<Centre>& all, const RunResult& run, bool departed) {
  const std::vector<Centre> centres = measured_about(all);
  for (std::size_t k = 0; k < centres.size(); ++k) {
    const double r0 = start_distance(body, centres[k]);
    const Vec3 G = detail::guiding_centre(body.p, run.final) - centres[k].c;
    const auto particle = kepler_particle(body.p, run.final, centres[k].c);
    const bool receding = particle && particle->X.dot(particle->P) > 0.0;
    if (receding && (departed || G.norm() >= r0 * (1.0 - kLeftSlack))) continue;
    const std::string where = centres.size() > 1 ? " from centre " + std::to_string(k) : "";
    return "the run ended at t = " + fmt(run.t_end) + " with the " + (body.p.B == 0.0 ? "body" : "guiding centre") +
           " at distance " + fmt(G.norm()) + where + ", " + (receding ? "receding" : "not receding") +
           ", against " + fmt(r0) + " at the start: the encounter did not finish (run longer, or to its departure)";
  }
  return "";
}

/// The first hit (with `last`: the last) of an event of `kind` through `value` (not a stop), or nullptr.
const EventHit* marker(const std::vector<EventHit>& hits, const std::vector<Event>& events, Event::Kind kind, double value,
                       bool last) {
  const EventHit* found = nullptr;
  for (const EventHit& h : hits) {
    const Event& e = events[h.event];
    if (e.kind == kind && !e.stop && e.value == value && (!found || last)) found = &h;
  }
  return found;
}

/// A material point's asymptotes are exact but for their formula's rounding: Lv = X x P at the distance r
/// carries eps r |P| against its size b |P|, and the direction with it (B = 0, b = 1: the deflections from
/// L = 200 and 1600 differ by 5.0e-13, 4 eps (r0 + r1)/b = 3.2e-12 for the two).
constexpr double kKeplerRounding = 4.0;

void estimate_asymptote_error(Encounter& e, const Body& body, const std::vector<Centre>& centres, const State& end,
                              const std::vector<EventHit>& hits, const std::vector<Event>& events) {
  if (!std::isfinite(e.scattering.deflection)) {
    e.asymptote_basis = "not known: no asymptotes";
    return;
  }
  if (body.p.B == 0.0 && centres.size() == 1) {
    const Vec3& c = centres.front().c;
    const double b = e.scattering.b, r = (body.s0.R - c).norm() + (end.R - c).norm();
    e.asymptote_error = b > 0.0 ? kKeplerRounding * std::numeric_limits<double>::epsilon() * r / b : 0.0;
    e.b_error = e.asymptote_error * b;  // the same rounding, relative
    e.v_inf_error = kKeplerRounding * std::numeric_limits<double>::epsilon() * e.scattering.v_inf;
    e.out_of_plane_model_error = e.asymptote_error;
    e.asymptote_basis = "exact: a material point's asymptotes are its Kepler orbit's (the rounding of their formula at "
                        "the run's distances: 4 eps (r0 + r1)/b)";
    return;
  }
  const double half = 0.5 * start_distance(body, measured_about(centres).front());
  const EventHit* in = marker(hits, events, Event::Kind::arrival, half, false);
  const EventHit* out = marker(hits, events, Event::Kind::departure, half, true);
  if (!in || !out || out->t <= in->t) {
    e.asymptote_basis = "not known: the guiding centre did not pass half its start distance (" + fmt(half) + ") both ways";
    return;
  }
  const Scattering at_half = scattering(body.p, centres, in->s, out->s);
  const double fall = std::pow(2.0, kAsymptoteFall) - 1.0;
  e.asymptote_error = std::abs(e.scattering.deflection - at_half.deflection) / fall;
  // The incoming asymptote's b and v_inf the same way (b from K2Q, v_inf from the energy: their model error
  // falls faster still, 11x a doubling from L = 200 on table 3.1, b = 3).
  e.b_error = std::abs(e.scattering.b - at_half.b) / fall;
  e.v_inf_error = std::abs(e.scattering.v_inf - at_half.v_inf) / fall;
  e.out_of_plane_model_error = std::abs(e.scattering.out_of_plane - at_half.out_of_plane) / fall;
  e.asymptote_basis = "deflection at the run's ends against at half the start distance (" + fmt(half) + "), over 2^" +
                      fmt(kAsymptoteFall) + " - 1";
}

}  // namespace

double time_delay_run_error(const Body& body, const std::vector<Centre>& centres, const ErrorEstimate& error, double t_end) {
  if (!std::isnan(error.time_delay) || !error.pair) return error.time_delay;
  const auto delay = [&](const State& s, double t) { return scattering(body.p, centres, body.s0, s, t).time_delay; };
  const ErrorEstimate::Pair& p = *error.pair;
  return error.quantity(delay(p.run, p.t_run), delay(p.companion, p.t_companion), kTimeDelayRounding * std::abs(t_end));
}

Options encounter_options(const Body& body, const std::vector<Centre>& centres, Options options, bool stop_at_departure) {
  using K = Event::Kind;
  for (std::size_t k = 0; k < centres.size(); ++k)
    if (!has_event(options.events, K::closest_approach, k, false)) options.events.push_back(Event{K::closest_approach, k});
  const std::vector<Centre> about = measured_about(centres);
  if (about.size() != 1) return options;
  // Several centres: the distances from their far-field centre (Event::about).
  const std::optional<Vec3> point = centres.size() > 1 ? std::optional<Vec3>(about.front().c) : std::nullopt;
  const double half = 0.5 * start_distance(body, about.front());
  Event in{K::arrival, 0, half}, out{K::departure, 0, half};
  in.about = out.about = point;
  options.events.push_back(in);
  options.events.push_back(out);
  if (stop_at_departure && !has_event(options.events, K::departure, 0, true)) {
    Event leave{K::departure, 0, 0.0};
    leave.stop = true;
    leave.about = point;
    options.events.push_back(leave);
  }
  return options;
}

Encounter measure_encounter(const Body& body, const std::vector<Centre>& centres, const BodyResult& r,
                            const std::vector<Event>& events) {
  const RunResult& run = r.run;
  const std::vector<EventHit>& hits = r.events;
  Encounter e;
  e.scattering = scattering(body.p, centres, body.s0, run.final, run.t_end);
  e.time_delay_run_error = time_delay_run_error(body, centres, r.error, run.t_end);
  if (const EventHit* nearest = nearest_approach(hits, events)) {
    e.r_min = nearest->r;
    e.t_min = nearest->t;
    e.r_min_error = nearest->r_error;
    e.t_min_error = nearest->t_error;
  }
  const bool departed = run.stopped && !hits.empty() && events[hits.back().event].kind == Event::Kind::departure &&
                        events[hits.back().event].stop;
  e.reason = unfinished(body, centres, run, departed);
  const bool finished = e.reason.empty();
  // A scattering result exists only for an encounter that happened: a body (guiding centre) that
  // drifts away from the start passes no closest approach, and its "incoming" asymptote is a leg it
  // never travelled (v_inf = 1 on table 3.1 had solved such a start, deflection 0.445 reported).
  if (finished && !nearest_approach(hits, events))
    e.reason = "no encounter happened: the distance to the centres has no minimum within the run (the " +
               std::string(body.p.B == 0.0 ? "body" : "guiding centre") + " recedes from the start)";
  if (!e.reason.empty()) {
    e.outcome = Outcome::incomplete;
    Scattering& sc = e.scattering;
    const std::string none = finished ? "no encounter happened" : "the encounter did not finish";
    if (sc.in) sc.asymptotes = "none: " + none;
    sc.in.reset();
    sc.out.reset();
    sc.deflection = sc.out_of_plane = sc.b = sc.v_inf = sc.time_delay = Scattering::kNaN;
    e.asymptote_basis = "not known: " + none;
    return e;
  }
  estimate_asymptote_error(e, body, centres, run.final, hits, events);
  return e;
}

double encounter_span(const Body& body, const std::vector<Centre>& centres) {
  const std::optional<Centre> far = far_field_centre(centres);
  if (!far) throw Error("an encounter without an end time t_end needs Coulomb centres (give t_end)");
  const auto k = kepler_particle(body.p, body.s0, far->c);
  const auto a = k ? kepler_asymptote(k->mu, k->kappa(far->A), k->X, k->P, false) : std::nullopt;
  if (!a) throw Error("the body has no speed at infinity (a bound orbit, or a guiding centre at rest): give t_end");
  return kEncounterSpans * 2.0 * k->X.norm() / (a->p_inf / k->mu);
}

void add_start_distance_error(Encounter& at_L, const EncounterResult* at_2L, bool material, double numerical, bool at_limit) {
  at_L.time_delay_error = Scattering::kNaN;
  if (material) {
    at_L.start_distance_error = at_L.out_of_plane_start_error = 0.0;
    at_L.time_delay_error = at_L.time_delay_run_error;
    at_L.start_distance_basis = "exact: a material point's Kepler hyperbola is that of its states, wherever they are";
  } else if (!at_2L || at_2L->run.outcome != Outcome::ok || at_2L->encounter.outcome != Outcome::ok ||
             !std::isfinite(at_2L->encounter.scattering.deflection)) {
    const std::string why = !at_2L ? "" : at_2L->run.outcome != Outcome::ok ? at_2L->run.reason : at_2L->encounter.reason;
    at_L.start_distance_basis = "not known: the encounter from twice the start distance did not finish" +
                                (why.empty() ? std::string() : " (" + why + ")");
  } else if (at_limit) {
    // The value at the limit, 2 x(2L) - x(L); the far run's errors count twice in it.
    const Encounter& far = at_2L->encounter;
    Scattering& sc = at_L.scattering;
    const double far_error = (std::isfinite(at_2L->run.error.for_orbit()) ? at_2L->run.error.for_orbit() : 0.0) +
                             (std::isfinite(far.asymptote_error) ? far.asymptote_error : 0.0);
    // x at the limit, and its error without the far run's: kLimitFactor |x(L) - x(2L)|.
    const auto to_limit = [](double& x, double x_far) {
      const double error = kLimitFactor * std::abs(x - x_far);
      x = 2.0 * x_far - x;
      return error;
    };
    at_L.start_distance_error = to_limit(sc.deflection, far.scattering.deflection) + 2.0 * far_error;
    at_L.out_of_plane_start_error = to_limit(sc.out_of_plane, far.scattering.out_of_plane) + 2.0 * far_error;
    // The delay's run parts: this run's, and the far run's twice.
    at_L.time_delay_error = to_limit(sc.time_delay, far.scattering.time_delay) + at_L.time_delay_run_error +
                            2.0 * far.time_delay_run_error;
    at_L.start_distance_basis = "at the limit L -> infinity: 2 x(2L) - x(L) from the encounter started at twice the distance (" +
                                fmt(far.scattering.deflection) + " rad there, estimated error " + fmt(far_error) +
                                "), within 1.5 |x(L) - x(2L)| and twice that run's error";
  } else {
    // x(L) = x_inf + c/L: x(L) - x_inf = 2 (x(L) - x(2L)), with a margin; the far run's own error counts.
    const Scattering& far = at_2L->encounter.scattering;
    const double far_error = std::isfinite(at_2L->run.error.for_orbit()) ? at_2L->run.error.for_orbit() : 0.0;
    at_L.start_distance_error = kStartDistanceFactor * (std::abs(at_L.scattering.deflection - far.deflection) + far_error);
    at_L.time_delay_error = kStartDistanceFactor * (std::abs(at_L.scattering.time_delay - far.time_delay) +
                                                    at_2L->encounter.time_delay_run_error) +
                            at_L.time_delay_run_error;
    at_L.out_of_plane_start_error = kStartDistanceFactor * (std::abs(at_L.scattering.out_of_plane - far.out_of_plane) + far_error);
    at_L.start_distance_basis = "3 |x(L) - x(2L)| from the encounter started at twice the distance (" + fmt(far.deflection) +
                                " rad there, estimated error " + fmt(far_error) +
                                "): the observables converge as 1/L, a margin of 1.5 for the next order";
  }
  at_L.deflection_error = numerical + at_L.asymptote_error + at_L.start_distance_error;  // NaN if any is
  at_L.out_of_plane_error = numerical + at_L.out_of_plane_model_error + at_L.out_of_plane_start_error;
}

namespace {

/// An encounter run to its departure (or t_end) at the accuracy `a`, as encounter() runs it (with `twice` beside
/// it where far legs serve both).
EncounterResult encounter_at(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method, Accuracy a,
                             Options options, bool to_departure, TwiceAsFar* twice = nullptr) {
  const Options o = encounter_options(body, centres, std::move(options), to_departure);
  check_request(Scene{centres, {body}}, method, a, o);
  EncounterResult r{detail::integrate_encounter_checked(body, centres, method, a, o, twice), {}, o.events};
  if (r.run.outcome != Outcome::ok) {
    r.encounter.outcome = r.run.outcome;
    r.encounter.reason = r.run.reason;
    return r;
  }
  r.encounter = measure_encounter(body, centres, r.run, o.events);
  return r;
}

/// The options of the encounter from 2L: the caller's, without the events' errors (its observables are what the
/// limit needs, not its closest approach's error).
Options twice_as_far_options(Options o) {
  o.estimate_events = false;
  return o;
}

}  // namespace

EncounterResult encounter_twice_as_far(const Scene& far, double tol, const Options& options, const BodyResult* near) {
  constexpr double kLooser = 100.0, kLoosest = 1e-6;
  const Body& body = far.bodies.front();
  const double span = encounter_span(body, far.centres);
  for (Accuracy a{tol, span};; a.tol *= kLooser) {
    // The same encounter from L: its near field is this one's, so its delivered step is where this search starts
    // (a map's plan, Accuracy::first_step) wherever auto chooses the same method for it (first_step_of): the
    // whole run from 2L, or with far legs the run between them, which asks the same share of tol as the run
    // from L did. A step delivered for a tighter tol is a plan too (the search coarsens a pair far below it).
    const bool plan = near && near->accuracy && near->method && near->accuracy->tol <= a.tol;
    a.first_step = plan ? near->accuracy->h_chosen : 0.0;
    a.first_step_of = plan ? near->method : nullptr;
    EncounterResult r = encounter_at(body, far.centres, nullptr, a, twice_as_far_options(options), true);
    if (r.run.outcome != Outcome::failed || r.run.reason.find("out of reach") == std::string::npos ||
        a.tol * kLooser > kLoosest)
      return r;
  }
}

std::optional<TwiceAsFar> twice_as_far_beside(const std::function<Expected<Scene>()>& far, bool at_limit, const Body& body,
                                              const std::vector<Centre>& centres, std::optional<double> tol,
                                              const Options& options) {
  if (!far || !at_limit || !tol || body.p.B == 0.0) return std::nullopt;
  const Expected<Scene> scene = far();
  if (!scene || scene->bodies.size() != 1 || scene->centres.size() != centres.size()) return std::nullopt;
  const Body& twice = scene->bodies.front();
  return TwiceAsFar{twice, scene->centres, encounter_options(twice, scene->centres, twice_as_far_options(options), true), std::nullopt};
}

EncounterResult encounter_beside(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method, double tol,
                                 Options options, TwiceAsFar* twice) {
  return encounter_at(body, centres, method, Accuracy{tol, encounter_span(body, centres)}, std::move(options), true, twice);
}

namespace {

/// The closest approach's distance from the limit L -> infinity: r(L) converges to it neither as 1/L nor always
/// monotonically (the helix's phase at the periapsis moves with L: B = 0.416, A = -2.946, b = 1.64, arrival phase
/// 3.07 by logh-kl6 at 1e-10 from L = 200, 300, 400, 600: 3.17143188862, 3.17143207244, 3.17143198370,
/// 3.17143182675, the limit about 3.1714318756; 2 r(400) - r(200) is 2.0e-7 off it, 1.4x 1.5 |r(200) - r(400)|), so
/// it is not taken to the limit as the deflection is: its error adds kStartDistanceFactor (|r(L) - r(2L)| + the run
/// from 2L's error), as a scene's start distance part where it is not at the limit. That run locates it without an
/// error of its own (twice_as_far_options): the same near field at the same tol, its location's error is taken as
/// this run's, but where the two share the run between their far legs (`shared`: this run's error carries its
/// location and the hand-off); its legs' part is its own (far_legs.cpp, approach_error). Its time is from this start.
void closest_from_limit(Encounter& e, const EncounterResult& twice, bool shared) {
  const Encounter& far = twice.encounter;
  if (!std::isfinite(e.r_min) || !std::isfinite(far.r_min)) return;
  const double far_error = (shared ? 0.0 : e.r_min_error) + twice.run.error.closest_from_legs;  // NaN: not known
  e.r_min_error += kStartDistanceFactor * (std::abs(e.r_min - far.r_min) + far_error);
}

}  // namespace

void no_start_distance_error(Encounter& e, bool material, double numerical, const std::string& why) {
  add_start_distance_error(e, nullptr, material, numerical, false);
  if (!material) e.start_distance_basis = "not known: " + why;
}

long add_start_distance(Encounter& e, const Body& body, const std::function<Expected<Scene>()>& far,
                        std::optional<double> tol, double numerical, const std::string& no_far, const Options& options,
                        bool at_limit, const BodyResult* near, const TwiceAsFar* twice) {
  // A material point's Kepler hyperbola is that of its states, wherever they are: a scene given by its
  // start state has the observables of that trajectory, and one given by asymptotic data keeps K1 as its
  // momentum at infinity (speed_at_infinity_of), so no start distance changes them. A scene that gives
  // states (a scene file) has no start distance to double: its observables are its trajectory's, their
  // error the run's and the asymptotes' (issue #79: a spinning body's was "not known").
  if (!far || body.p.B == 0.0) {
    add_start_distance_error(e, nullptr, true, numerical);
    if (!far) e.start_distance_basis = "none: " + no_far + "; its observables are its trajectory's";
    return 0;
  }
  EncounterResult r;
  if (twice && twice->run) {  // run beside the encounter from L (far legs)
    r.run = *twice->run;
    r.events = twice->options.events;
    if (r.run.outcome == Outcome::ok) r.encounter = measure_encounter(twice->body, twice->centres, r.run, r.events);
    // Each encounter's observables as its own run's to first order (the limit is the same either way).
    const auto shift = [](double& at_L, double& at_2L, double by) {
      at_2L -= by;
      at_L -= 2.0 * by;
    };
    Scattering &sc = e.scattering, &far_sc = r.encounter.scattering;
    shift(sc.deflection, far_sc.deflection, twice->deflection_shift);
    shift(sc.time_delay, far_sc.time_delay, twice->time_delay_shift);
    shift(sc.out_of_plane, far_sc.out_of_plane, twice->out_of_plane_shift);
  } else {
    // The scene from 2L solved once: the one twice_as_far_beside made, where it made one.
    const Expected<Scene> scene = twice ? Expected<Scene>(Scene{twice->centres, {twice->body}}) : far();
    if (!scene) {  // no scene from 2L has the data: the part is not known, and why
      no_start_distance_error(e, false, numerical, "the scene from twice the start distance has no such data (" + scene.error() + ")");
      return 0;
    }
    r = encounter_twice_as_far(*scene, twice_as_far_tol(tol), options, near);
  }
  add_start_distance_error(e, &r, false, numerical, at_limit);
  if (at_limit && r.encounter.outcome == Outcome::ok) closest_from_limit(e, r, twice && twice->run);
  if (twice && twice->run)
    e.start_distance_basis += "; the two share the run between their far legs, from the hand-off at the limit 2 S(2L) - S(L) (each "
                              "its own legs), which the limit cancels to first order";
  e.start_distance_force_evals = r.run.total_force_evals();
  return e.start_distance_force_evals;
}

Expected<Scene> thesis_scene_twice_as_far(SceneParams solved, double b, double v_inf, double arrival_phase) {
  // The limit L -> infinity is of the scene as given: its K1 or v_inf, its d or b, kept. Its start phase
  // has no limit (the helix turns on the longer way in: doubling L moves the arrival phase by whatever
  // the extra turn is), so where no arrival phase is given the scene's own at L is kept instead.
  if (std::isnan(arrival_phase) && solved.B != 0.0) {
    const Expected<double> own = solve_arrival_phase(solved);
    if (!own) return Expected<Scene>::failure(own.error());
    arrival_phase = *own;
  }
  // The speed at infinity is the scene's own at L where none was given (solve_asymptotic_data reads K1 as the
  // momentum at infinity, and `solved` has the K1 solved at L for it).
  if (std::isnan(v_inf) && !(std::isnan(b) && std::isnan(arrival_phase))) {
    const Expected<double> own = incoming_speed(solved);
    if (!own) return Expected<Scene>::failure(own.error());
    v_inf = *own;
  }
  solved.start.L *= 2.0;
  const Expected<SceneParams> far = solve_asymptotic_data(solved, b, v_inf, arrival_phase);
  if (!far) return Expected<Scene>::failure(far.error());
  return valid_thesis_scene(*far);
}

EncounterResult encounter(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method, double tol,
                          double t_end, Options options) {
  const bool to_departure = std::isnan(t_end);
  // An encounter is measured forwards in time (a negative t_end ran backwards, then read "did not finish").
  if (!to_departure) require_positive(t_end, "an encounter's end time t_end");
  return encounter_at(body, centres, method, Accuracy{tol, to_departure ? encounter_span(body, centres) : t_end},
                      std::move(options), to_departure);
}

}  // namespace bodypoint
