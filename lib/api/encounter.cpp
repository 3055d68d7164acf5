// bodypoint: an encounter measured on a run (bodypoint.hpp, Encounter; scattering.hpp).
#include "bodypoint/bodypoint.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/scattering.hpp"
#include "bodypoint/detail/model_parts.hpp"
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

double start_distance(const Body& body, const Centre& c) { return (detail::guiding_centre(body.p, body.s0) - c.c).norm(); }

bool has_event(const std::vector<Event>& events, Event::Kind kind, std::size_t centre, bool stop) {
  return std::any_of(events.begin(), events.end(),
                     [&](const Event& e) { return e.kind == kind && e.centre == centre && e.stop == stop; });
}

/// Why the run ended before the body left, or empty when it had left.
std::string unfinished(const Body& body, const std::vector<Centre>& centres, const RunResult& run) {
  for (std::size_t k = 0; k < centres.size(); ++k) {
    const double r0 = start_distance(body, centres[k]);
    const Vec3 G = detail::guiding_centre(body.p, run.final) - centres[k].c;
    const auto particle = kepler_particle(body.p, run.final, centres[k].c);
    const bool receding = particle && particle->X.dot(particle->P) > 0.0;
    if (receding && G.norm() >= r0 * (1.0 - kLeftSlack)) continue;
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
  if (body.p.B == 0.0) {
    const Vec3& c = centres.front().c;
    const double b = e.scattering.b, r = (body.s0.R - c).norm() + (end.R - c).norm();
    e.asymptote_error = b > 0.0 ? kKeplerRounding * std::numeric_limits<double>::epsilon() * r / b : 0.0;
    e.asymptote_basis = "exact: a material point's asymptotes are its Kepler orbit's (the rounding of their formula at "
                        "the run's distances: 4 eps (r0 + r1)/b)";
    return;
  }
  const double half = 0.5 * start_distance(body, centres.front());
  const EventHit* in = marker(hits, events, Event::Kind::arrival, half, false);
  const EventHit* out = marker(hits, events, Event::Kind::departure, half, true);
  if (!in || !out || out->t <= in->t) {
    e.asymptote_basis = "not known: the guiding centre did not pass half its start distance (" + fmt(half) + ") both ways";
    return;
  }
  const double theta_half = scattering(body.p, centres, in->s, out->s).deflection;
  e.asymptote_error = std::abs(e.scattering.deflection - theta_half) / (std::pow(2.0, kAsymptoteFall) - 1.0);
  e.asymptote_basis = "deflection at the run's ends against at half the start distance (" + fmt(half) + "), over 2^" +
                      fmt(kAsymptoteFall) + " - 1";
}

}  // namespace

Options encounter_options(const Body& body, const std::vector<Centre>& centres, Options options, bool stop_at_departure) {
  using K = Event::Kind;
  for (std::size_t k = 0; k < centres.size(); ++k)
    if (!has_event(options.events, K::closest_approach, k, false)) options.events.push_back(Event{K::closest_approach, k});
  if (centres.size() != 1) return options;
  const double half = 0.5 * start_distance(body, centres.front());
  options.events.push_back(Event{K::arrival, 0, half});
  options.events.push_back(Event{K::departure, 0, half});
  if (stop_at_departure && !has_event(options.events, K::departure, 0, true)) {
    Event leave{K::departure, 0, 0.0};
    leave.stop = true;
    options.events.push_back(leave);
  }
  return options;
}

Encounter measure_encounter(const Body& body, const std::vector<Centre>& centres, const RunResult& run,
                            const std::vector<EventHit>& hits, const std::vector<Event>& events) {
  Encounter e;
  e.scattering = scattering(body.p, centres, body.s0, run.final, run.t_end);
  if (const EventHit* nearest = nearest_approach(hits, events)) {
    e.r_min = nearest->r;
    e.t_min = nearest->t;
  }
  e.reason = unfinished(body, centres, run);
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
  if (centres.size() != 1) throw Error("an encounter without an end time t_end needs a single centre (give t_end)");
  const auto k = kepler_particle(body.p, body.s0, centres.front().c);
  const auto a = k ? kepler_asymptote(k->mu, k->kappa(centres.front().A), k->X, k->P, false) : std::nullopt;
  if (!a) throw Error("the body has no speed at infinity (a bound orbit, or a guiding centre at rest): give t_end");
  return kEncounterSpans * 2.0 * k->X.norm() / (a->p_inf / k->mu);
}

void add_start_distance_error(Encounter& at_L, const EncounterResult* at_2L, bool material, double numerical) {
  if (material) {
    at_L.start_distance_error = at_L.time_delay_error = 0.0;
    at_L.start_distance_basis = "exact: a material point's Kepler hyperbola is that of its states, wherever they are";
  } else if (!at_2L || at_2L->run.outcome != Outcome::ok || at_2L->encounter.outcome != Outcome::ok ||
             !std::isfinite(at_2L->encounter.scattering.deflection)) {
    const std::string why = !at_2L ? "" : at_2L->run.outcome != Outcome::ok ? at_2L->run.reason : at_2L->encounter.reason;
    at_L.start_distance_basis = "not known: the encounter from twice the start distance did not finish" +
                                (why.empty() ? std::string() : " (" + why + ")");
  } else {
    // x(L) = x_inf + c/L: x(L) - x_inf = 2 (x(L) - x(2L)), with a margin; the far run's own error counts.
    const Scattering& far = at_2L->encounter.scattering;
    const double far_error = std::isfinite(at_2L->run.error.value) ? at_2L->run.error.value : 0.0;
    at_L.start_distance_error = kStartDistanceFactor * (std::abs(at_L.scattering.deflection - far.deflection) + far_error);
    at_L.time_delay_error = kStartDistanceFactor * std::abs(at_L.scattering.time_delay - far.time_delay);
    at_L.start_distance_basis = "3 |x(L) - x(2L)| from the encounter started at twice the distance (" + fmt(far.deflection) +
                                " rad there, estimated error " + fmt(far_error) +
                                "): the observables converge as 1/L, a margin of 1.5 for the next order";
  }
  at_L.deflection_error = numerical + at_L.asymptote_error + at_L.start_distance_error;  // NaN if any is
}

EncounterResult encounter_twice_as_far(const Scene& far, double tol, const Options& options) {
  constexpr double kLooser = 100.0, kLoosest = 1e-6;
  for (;; tol *= kLooser) {
    EncounterResult r = encounter(far.bodies.front(), far.centres, nullptr, tol, Scattering::kNaN, options);
    if (r.run.outcome != Outcome::failed || r.run.reason.find("out of reach") == std::string::npos ||
        tol * kLooser > kLoosest)
      return r;
  }
}

void no_start_distance_error(Encounter& e, bool material, double numerical, const std::string& why) {
  add_start_distance_error(e, nullptr, material, numerical);
  if (!material) e.start_distance_basis = "not known: " + why;
}

long add_start_distance(Encounter& e, const Body& body, const std::function<Expected<Scene>()>& far,
                        std::optional<double> tol, double numerical, const std::string& no_far, const Options& options) {
  // A material point's Kepler hyperbola is that of its states, wherever they are: a scene given by its
  // start state has the observables of that trajectory, and one given by asymptotic data keeps K1 as its
  // momentum at infinity (speed_at_infinity_of), so no start distance changes them.
  if (!far || body.p.B == 0.0) {
    no_start_distance_error(e, body.p.B == 0.0, numerical, no_far);
    return 0;
  }
  const Expected<Scene> scene = far();
  if (!scene) {  // no scene from 2L has the data: the part is not known, and why
    no_start_distance_error(e, false, numerical, "the scene from twice the start distance has no such data (" + scene.error() + ")");
    return 0;
  }
  const EncounterResult r = encounter_twice_as_far(*scene, twice_as_far_tol(tol), options);
  add_start_distance_error(e, &r, false, numerical);
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
  const double end = to_departure ? encounter_span(body, centres) : t_end;
  const Options o = encounter_options(body, centres, std::move(options), to_departure);
  EncounterResult r{integrate_body(body, centres, method, Accuracy{tol, end}, o), {}, o.events};
  if (r.run.outcome != Outcome::ok) {
    r.encounter.outcome = r.run.outcome;
    r.encounter.reason = r.run.reason;
    return r;
  }
  r.encounter = measure_encounter(body, centres, r.run.run, r.run.events, o.events);
  return r;
}

}  // namespace bodypoint
