// bodypoint: integrate() and Stepper, the public API's runs (bodypoint.hpp).
#include "bodypoint/bodypoint.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/field.hpp"
#include "bodypoint/detail/monitor.hpp"
#include "checked.hpp"
#include "choice.hpp"
#include "estimate.hpp"
#include "events.hpp"
#include "bodypoint/detail/run_parts.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>
#include <type_traits>
#include <utility>

namespace bodypoint {

long BodyResult::total_force_evals() const {
  return (accuracy ? accuracy->force_evals : run.force_evals) + error.force_evals + event_force_evals + encounter_force_evals;
}

namespace {

/// The accuracy mode: the step search, whose delivered run carries the observers.
void run_accurately(BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Accuracy& a,
                    const Options& options) {
  // One search rule whoever named the method: the method auto chooses for this scene and tol is not
  // verified about one centre (its estimates there were measured honest: bench/estimate_grid.py), any
  // other is, against a companion at half the delivered step (auto_verifies, methods.hpp). logh-kl6
  // named at tol 1e-9 on an encounter was refused where auto delivered it.
  const bool unverified = r.method == &detail::choose_method_for(body, centres, a.tol, nullptr) && !auto_verifies(centres);
  Accuracy planned = a;
  if (a.first_step_of && a.first_step_of != r.method) planned.first_step = 0.0;  // another method's step
  adaptive::ToleranceResult t = adaptive::search_step(*r.method, body, centres, planned, options, !unverified);
  r.accuracy = AccuracyReport{a.tol, t.err_estimate, t.h, t.omega_c, t.runs, t.total_force_evals, t.total_wall_s,
                              std::move(t.basis)};
  if (t.companion) r.error.pair = ErrorEstimate::Pair{t.result.final, t.companion->final, t.result.t_end, t.companion->t_end};
  r.run = std::move(t.result);
}

BodyResult run_plain(const Body& body, const std::vector<Centre>& centres, const MethodInfo& m, const Advance& how,
                     const Options& options);
BodyResult run_timed(const Body& body, const std::vector<Centre>& centres, const MethodInfo& m, const Advance& how,
                     const Options& options);

/// Whether an event's first bracket ends the run: a stop event, except the closest approach, which is the
/// least distance of the whole run (it is cut there afterwards: run_watched).
bool ends_run(const Event& e) { return e.stop && e.kind != Event::Kind::closest_approach; }

/// The sink of a run with events: every observed state goes to the watch; the caller's sink gets the
/// states it asked for (every `every`-th step and the last; with dt_out all of them). Once a stop
/// event is bracketed no later state is passed on; with `stop_run` the run is ended there (Flow::stop).
/// A run that stops at its closest approach knows where only at its end: its states are held until then
/// and those before the approach handed on (the caller's Flow::stop ends them, not the run).
class WatchingSink {
 public:
  WatchingSink(detail::EventWatch& watch, const Options& options, bool every_state, bool stop_run)
      : watch_(watch), events_(options.events), user_(options.sink), every_(every_state ? 1 : options.every),
        stop_run_(stop_run), hold_(std::any_of(events_.begin(), events_.end(), [](const Event& e) {
          return e.stop && e.kind == Event::Kind::closest_approach;
        })) {}
  Flow operator()(const Sample& s) {
    if (stopped_) return Flow::go;
    watch_.observe(s.t, s.s);
    for (; seen_ < watch_.brackets().size(); ++seen_)
      stopped_ = stopped_ || ends_run(events_[watch_.brackets()[seen_].event]);
    if (stopped_) {
      pending_.reset();
      stop_step_ = s.step;
      return stop_run_ ? Flow::stop : Flow::go;
    }
    if (!user_ || s.inside) return Flow::go;  // a state inside a step is the watch's alone
    if (s.step % every_ != 0) {
      pending_ = KeptSample::of(s);
      return Flow::go;
    }
    pending_.reset();
    if (hold_) {
      held_.push_back(KeptSample::of(s));
      return Flow::go;
    }
    return (*user_)(s);
  }
  /// The last state: the one the every-th rule skipped, or the stop event's (its deviations given); the
  /// states held for a stop at the closest approach before it.
  void finish(const EventHit* stop, double rel_dE, double rel_dK2sq, double abs_dK2Q) {
    if (!user_) return;
    for (const KeptSample& k : held_) {
      if (stop && k.t >= stop->t) {
        stop_step_ = k.step;
        break;
      }
      stop_step_ = k.step;
      if ((*user_)(k.sample()) == Flow::stop) return;
    }
    if (stop) (*user_)(Sample{stop_step_, stop->t, stop->s, rel_dE, rel_dK2sq, abs_dK2Q});
    else if (pending_) (*user_)(pending_->sample());
  }

 private:
  detail::EventWatch& watch_;
  const std::vector<Event>& events_;
  const SampleSink* user_;
  long every_;
  bool stop_run_;
  bool hold_;                     ///< a stop at the closest approach: the caller's states wait for the run's end
  std::vector<KeptSample> held_;
  bool stopped_ = false;
  std::size_t seen_ = 0;
  long stop_step_ = 0;
  std::optional<KeptSample> pending_;
};

/// A run cut at its stop event `hit` (a state of the run's own steps): the final state and time are
/// the event's, the invariants' deviations include it. Returns those deviations (for the last sample).
InvariantStats cut_at(RunResult& run, const EventHit& hit, const Body& body, const std::vector<Centre>& centres) {
  run.final = hit.s;
  run.t_end = hit.t;
  run.stopped = true;
  const CentreList field{centres};
  InvariantMonitor<CentreList> mon(body.p, field, body.s0);
  mon.update(hit.s);
  InvariantStats last{mon.last_rel_dE(), mon.last_rel_dK2sq(), mon.last_abs_dK2Q()};
  if (run.invariants) {
    InvariantStats& s = *run.invariants;
    s.max_rel_dE = InvariantMonitor<CentreList>::max_keeping_nan(s.max_rel_dE, last.max_rel_dE);
    s.max_rel_dK2sq = InvariantMonitor<CentreList>::max_keeping_nan(s.max_rel_dK2sq, last.max_rel_dK2sq);
    if (s.has_K2Q) s.max_abs_dK2Q = InvariantMonitor<CentreList>::max_keeping_nan(s.max_abs_dK2Q, last.max_abs_dK2Q);
  }
  return last;
}

/// The run's configuration for a time tau from a state: what locates its events (events.hpp).
detail::Advancer advancer(const BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                          const Options& options) {
  const MethodInfo& m = *r.method;
  double step = 0.0, h0 = kControlledFirstStep, c = options.omega_c;  // step: h, ds or tol (advance_to)
  if (r.accuracy) {
    step = r.accuracy->h_chosen;
    c = r.accuracy->omega_c;
  } else if (const auto* fixed = std::get_if<FixedSteps>(&how)) {
    step = fixed->h;
  } else if (const auto* fictitious = std::get_if<FictitiousSteps>(&how)) {
    step = fictitious->ds;
    if (c < 0.0) c = automatic_omega_c(body, centres, step);
  } else if (const auto* controlled = std::get_if<ControlledSteps>(&how)) {
    step = controlled->tol;
    h0 = controlled->h0;
  }
  return [&m, body, &centres, step, h0, c, cancel = options.cancel](const State& s, double tau, long& evals) {
    Body from = body;
    from.s0 = s;
    Options sub;
    sub.track_invariants = false;
    sub.omega_c = c;
    sub.cancel = cancel;
    // A fixed step: one step of tau inside a step; steps <= h across output times.
    const BodyResult x = run_plain(from, centres, m, advance_to(m, step, tau, h0), sub);
    evals += x.run.force_evals;
    if (!ran(x.outcome)) {
      constexpr double nan = std::numeric_limits<double>::quiet_NaN();
      return State{Vec3::Constant(nan), Vec3::Constant(nan), Vec3::Constant(nan)};
    }
    return x.run.final;
  };
}

/// The sink of a fixed-step or step-size-controlled run with output times: it observes every step and
/// hands the caller the states at t = k dt_out, each from the step that contains it, taken again from
/// that step's start for the shorter time (the run's own method and configuration: `advance`), then
/// the last state. The time-transformed methods do the same inside their loop (FictitiousLoop).
class OutputTimesSink {
 public:
  OutputTimesSink(const Body& body, const std::vector<Centre>& centres, double dt_out, const SampleSink& user,
                  detail::Advancer advance)
      : field_{centres}, monitor_(body.p, field_, body.s0), dt_out_(dt_out), user_(user), advance_(std::move(advance)) {}
  Flow operator()(const Sample& x) {
    Flow flow = Flow::go;
    if (!prev_) {
      flow = emit(x);  // t = 0
      next_ = 1;
    } else {
      // The output times before a state inside the step (RunOptions::inside_steps) come before it; that
      // state is handed on as it is (the watch's), the next output times still taken from the step's start.
      for (double t = next_time(); (x.inside ? t < x.t : t <= x.t) && flow == Flow::go; t = next_time()) {
        if (t == x.t) {
          flow = emit(x);
        } else {
          const State s = advance_(prev_->s, t - prev_->t, evals_);
          monitor_.update(s);
          flow = user_(Sample{x.step, t, s, monitor_.last_rel_dE(), monitor_.last_rel_dK2sq(), monitor_.last_abs_dK2Q()});
          last_t_ = t;
        }
        ++next_;
      }
      if (x.inside) return flow == Flow::go ? user_(x) : flow;
    }
    prev_ = KeptSample::of(x);
    return flow;
  }
  /// The last state, unless it was an output time.
  void finish() {
    if (prev_ && prev_->t > last_t_) user_(prev_->sample());
  }
  [[nodiscard]] long evals() const { return evals_; }

 private:
  [[nodiscard]] double next_time() const { return static_cast<double>(next_) * dt_out_; }
  Flow emit(const Sample& x) {
    last_t_ = x.t;
    return user_(x);
  }
  CentreList field_;
  InvariantMonitor<CentreList> monitor_;
  double dt_out_;
  const SampleSink& user_;
  detail::Advancer advance_;
  long next_ = 0, evals_ = 0;
  double last_t_ = -1.0;
  std::optional<KeptSample> prev_;  ///< the last step's state, from which an output time inside the next is reached
};

/// A run with events: every observed state goes through the watch; the run itself is the one asked
/// for. A stop event ends a fixed-step, time-transformed or controlled run on the step that brackets
/// it; the accuracy mode hands its delivered run's states on after its search, so its run is cut at
/// the event afterwards.
BodyResult run_watched(const Body& body, const std::vector<Centre>& centres, const MethodInfo& m, const Advance& how,
                       const Options& options) {
  const bool accuracy = std::holds_alternative<Accuracy>(how);
  const std::vector<Event> events = detail::resolved(options.events, body.p, centres, body.s0);
  detail::EventWatch watch(events, body.p, centres);
  WatchingSink watching(watch, options, output_interval(how) > 0.0, !accuracy);
  const SampleSink sink = [&watching](const Sample& s) { return watching(s); };
  Options inner = options;
  inner.events.clear();
  inner.sink = &sink;
  inner.every = 1;
  inner.inside_steps = true;  // an event between the ends of a step that holds several turns of the spin
  BodyResult r = run_timed(body, centres, m, how, inner);
  if (!ran(r.outcome)) return r;
  r.events = detail::locate(watch, events, body.p, centres, advancer(r, body, centres, how, options), r.event_force_evals);
  detail::keep_closest(r.events, events);
  const auto stop = std::find_if(r.events.begin(), r.events.end(),
                                 [&](const EventHit& h) { return options.events[h.event].stop; });
  if (stop == r.events.end()) {
    watching.finish(nullptr, 0.0, 0.0, 0.0);
    return r;
  }
  r.events.erase(std::next(stop), r.events.end());  // nothing after the stop happened
  const InvariantStats last = cut_at(r.run, r.events.back(), body, centres);
  watching.finish(&r.events.back(), last.max_rel_dE, last.max_rel_dK2sq, last.max_abs_dK2Q);
  detail::judge(r, centres, options);
  return r;
}

/// The pilot that finds where an accuracy run's stop event falls: a step-size-controlled run (it needs no
/// step to be chosen, and stops stepping at the event) at this tolerance per step: the stop's time is needed
/// to a few per cent only (the search runs to twice it).
constexpr double kStopPilotTol = 1e-6;
/// The search then runs to twice that time, the span an encounter asks for by itself (two free passes): a
/// search just past the stop was measured to accept a ladder that the longer span refutes (b = 1, arrival
/// phase 0, TOL 1e-10: logh-kl6 delivered 9.1e-10 for an estimate of 4.2e-11 at 1.05x the stop's time,
/// refused "out of reach" over two passes). It plans only where the span asked for is longer than
/// kPlannedShorter times that, so an encounter asked to its own end is searched as before.
constexpr double kStopMargin = 2.0;
constexpr double kPlannedShorter = 1.5;
/// The pilot itself costs a share of the answer (odeint-dopri5 follows the helix), so it runs only where the
/// span asked for is over this many crossing times (the start's distance to the nearest centre over its
/// speed): an encounter's own span is 4 of them, and one asked to its departure within twice that is
/// searched whole, as before.
constexpr double kPilotAbove = 8.0;
/// The pilot's first trial step (the controller takes it up or down from there).
constexpr double kStopPilotFirstStep = 1e-3;

/// The time the body takes to cover its distance to the nearest centre at its start speed (infinite at rest).
/// The distance from R to the nearest centre (infinite without one).
double nearest_distance(const std::vector<Centre>& centres, const Vec3& R) {
  double r = std::numeric_limits<double>::infinity();
  for (const Centre& c : centres) r = std::min(r, (R - c.c).norm());
  return r;
}

double crossing_time(const Body& body, const std::vector<Centre>& centres) {
  const double r = nearest_distance(centres, body.s0.R);
  const double v = body.s0.v.norm();
  return v > 0.0 ? r / v : std::numeric_limits<double>::infinity();
}

/// The time of the first stop event of `options` on the way to a.t_end, found by the pilot (its force
/// evaluations added to `evals`), or nothing where the pilot did not reach it.
std::optional<double> stop_time(const Body& body, const std::vector<Centre>& centres, const Accuracy& a,
                                const Options& options, long& evals) {
  Options pilot;
  pilot.track_invariants = false;
  pilot.cancel = options.cancel;
  pilot.max_energy_error = std::numeric_limits<double>::infinity();
  for (const Event& e : options.events)
    if (e.stop) pilot.events.push_back(e);
  const BodyResult r = run_watched(body, centres, *find_method("odeint-dopri5"), ControlledSteps{kStopPilotFirstStep, a.t_end, kStopPilotTol}, pilot);
  evals += r.total_force_evals();
  if (r.outcome != Outcome::ok || !r.run.stopped) return std::nullopt;
  return r.run.t_end;
}

/// run_watched, with an accuracy run that has a stop event planned for the stop, not for the span asked
/// for (a departure asked with t_end = 1e5 searched its step over all of it): its search runs to
/// kStopMargin times the stop's time as a pilot finds it; a delivered run that does not reach the stop
/// there is searched again over the span asked for. Every evaluation is counted as the events'.
BodyResult run_with_events(const Body& body, const std::vector<Centre>& centres, const MethodInfo& m, const Advance& how,
                           const Options& options) {
  const auto* a = std::get_if<Accuracy>(&how);
  const bool stops = std::any_of(options.events.begin(), options.events.end(), [](const Event& e) { return e.stop; });
  if (!a || !stops || non_coulomb(centres) || !(a->t_end > kPilotAbove * crossing_time(body, centres)))
    return run_watched(body, centres, m, how, options);
  long spent = 0;
  const std::optional<double> t = stop_time(body, centres, *a, options, spent);
  if (t && kPlannedShorter * kStopMargin * *t < a->t_end) {
    Accuracy planned = *a;
    planned.t_end = kStopMargin * *t;
    BodyResult r = run_watched(body, centres, m, planned, options);
    r.event_force_evals += spent;
    if (!ran(r.outcome) || r.run.stopped) return r;
    spent = r.total_force_evals();
  }
  BodyResult r = run_watched(body, centres, m, how, options);
  r.event_force_evals += spent;
  return r;
}

/// A fixed-step or controlled run with output times: it observes every step, and OutputTimesSink
/// hands the caller the states at t = k dt_out.
BodyResult run_with_output_times(const Body& body, const std::vector<Centre>& centres, const MethodInfo& method,
                                 const Advance& how, const Options& options) {
  BodyResult probe;
  probe.method = &method;
  OutputTimesSink outputs(body, centres, output_interval(how), *options.sink,
                          advancer(probe, body, centres, how, options));
  const SampleSink sink = [&outputs](const Sample& x) { return outputs(x); };
  Options inner = options;
  inner.sink = &sink;
  inner.every = 1;
  Advance plain = how;
  std::visit([](auto& a) { a.dt_out = 0.0; }, plain);
  BodyResult r = run_plain(body, centres, method, plain, inner);
  if (!ran(r.outcome)) return r;
  outputs.finish();
  r.event_force_evals += outputs.evals();
  return r;
}

/// The accuracy mode with output times for a fixed-step method: the delivered run's states are kept
/// and handed on as a fixed-step run with output times hands them (OutputTimesSink), at the step the
/// search chose.
void run_accurately_at_output_times(BodyResult& r, const Body& body, const std::vector<Centre>& centres,
                                    const Accuracy& a, const Options& options) {
  std::vector<KeptSample> kept;
  const SampleSink keep = [&kept](const Sample& x) { kept.push_back(KeptSample::of(x)); };
  Options inner = options;
  inner.sink = &keep;
  inner.every = 1;
  Accuracy plain = a;
  plain.dt_out = 0.0;
  run_accurately(r, body, centres, plain, inner);
  OutputTimesSink outputs(body, centres, a.dt_out, *options.sink, advancer(r, body, centres, Advance(a), options));
  bool stopped = false;
  for (std::size_t i = 0; i < kept.size() && !stopped; ++i) stopped = outputs(kept[i].sample()) == Flow::stop;
  if (!stopped) outputs.finish();
  r.event_force_evals += outputs.evals();
}

// --- The run pipeline of a checked request, in order (integrate_estimated) ----------------------------------
//  1. the direction: a run backwards is the forward run of the time-reversed start, reversed back (in_direction);
//  2. the method: the one named or auto's choice, and its refusal of the scene (resolve_method);
//  3. the run, observed: its events watched (run_with_events), its output times (run_timed), the accuracy mode's
//     search or the method's own run (run_plain), each stage calling the next and none an earlier one;
//  4. its error estimate and its events' errors, from companion runs through stage 3 (estimate.hpp);
//  5. its outcome settled in the light of the estimate.
// A Stepper's segments enter at stage 3 with the method its construction resolved and checked (run_segment).

/// Stage 3's last step: the accuracy mode's search or the method's own run, judged by its flags.
BodyResult run_plain(const Body& body, const std::vector<Centre>& centres, const MethodInfo& m, const Advance& how,
                     const Options& options) {
  BodyResult r;
  r.method = &m;
  const auto* accuracy = std::get_if<Accuracy>(&how);
  try {
    if (accuracy && options.sink && accuracy->dt_out > 0.0 && !lands_on_output_times(m))
      run_accurately_at_output_times(r, body, centres, *accuracy, options);
    else if (accuracy) run_accurately(r, body, centres, *accuracy, options);
    else r.run = m.run(body, centres, how, options);
  } catch (const Error& e) {
    r.outcome = Outcome::failed;
    r.reason = e.what();
    return r;
  }
  detail::judge(r, centres, options);
  return r;
}

/// Stage 3 with output times: a fixed-step or controlled run hands its states at t = k dt_out through
/// OutputTimesSink; the others land on them themselves.
BodyResult run_timed(const Body& body, const std::vector<Centre>& centres, const MethodInfo& m, const Advance& how,
                     const Options& options) {
  if (!std::holds_alternative<Accuracy>(how) && options.sink && output_interval(how) > 0.0 && !lands_on_output_times(m))
    return run_with_output_times(body, centres, m, how, options);
  return run_plain(body, centres, m, how, options);
}

/// Stage 3 whole: with events, the watch around the run with output times.
BodyResult run_observed(const Body& body, const std::vector<Centre>& centres, const MethodInfo& m, const Advance& how,
                        const Options& options) {
  if (!options.events.empty()) return run_with_events(body, centres, m, how, options);
  return run_timed(body, centres, m, how, options);
}

/// Stage 2: the method named, or auto's choice for this body and tol (r.chosen says why); a refused request
/// comes back with its outcome and reason (r.method nullptr where auto chose none).
BodyResult resolve_method(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                          const Advance& how) {
  BodyResult r;
  r.method = method;
  const auto* accuracy = std::get_if<Accuracy>(&how);
  if (accuracy && non_coulomb(centres)) {
    r.outcome = Outcome::refused;
    r.reason = bodypoint::kNeedsCoulomb;
    return r;
  }
  if (!method) r.method = &detail::choose_method_for(body, centres, accuracy->tol, &r.chosen);
  if (std::string why = refusal(*r.method, body, centres); !why.empty()) {
    r.outcome = Outcome::refused;
    r.reason = std::move(why);
  }
  return r;
}

/// Stages 3-5 for a method resolved and accepted.
BodyResult run_estimated(const Body& body, const std::vector<Centre>& centres, const MethodInfo& m, const Advance& how,
                         const Options& options) {
  BodyResult r = run_observed(body, centres, m, how, options);
  const detail::Rerun rerun{[&](const Body& from, const Advance& a, const Options& o) {
    return run_observed(from, centres, m, a, o);
  }};
  detail::estimate_and_settle(r, body, centres, how, options, rerun);
  return r;
}

/// Stage 1 around `forwards(body, how, options)`, which runs a forward request: a run backwards in time
/// (is_backward) is the forward run of the time-reversed state (v, w negated), its states, times and events
/// reversed back: every method runs backwards, a symmetric splitting's steps being exactly its steps of -h.
template <class Forwards>
BodyResult in_direction(const Body& body, const Advance& how, const Options& options, const Forwards& forwards) {
  if (!is_backward(how)) return forwards(body, how, options);
  Body reversed = body;
  reversed.s0 = time_reversed(body.s0);
  Options o = options;
  SampleSink back;
  if (options.sink) {
    back = [&options](const Sample& x) {
      const State s = time_reversed(x.s);
      return (*options.sink)(Sample{x.step, -x.t, s, x.rel_dE, x.rel_dK2sq, x.abs_dK2Q, x.inside});
    };
    o.sink = &back;
  }
  BodyResult r = forwards(reversed, bodypoint::forwards(how), o);
  r.run.final = time_reversed(r.run.final);
  r.run.t_end = -r.run.t_end;
  if (ErrorEstimate::Pair* p = r.error.pair ? &*r.error.pair : nullptr)
    *p = {time_reversed(p->run), time_reversed(p->companion), -p->t_run, -p->t_companion};
  for (EventHit& h : r.events) {
    h.t = -h.t;
    h.s = time_reversed(h.s);
  }
  return r;
}

/// A checked request's run: the pipeline's five stages.
BodyResult integrate_estimated(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                               const Advance& how, const Options& options) {
  return in_direction(body, how, options, [&](const Body& b, const Advance& a, const Options& o) {
    BodyResult resolved = resolve_method(b, centres, method, a);
    if (resolved.outcome == Outcome::refused) return resolved;
    BodyResult r = run_estimated(b, centres, *resolved.method, a, o);
    r.chosen = std::move(resolved.chosen);
    return r;
  });
}

/// A Stepper's segment: stages 1 and 3-5 for the method its construction resolved and checked.
BodyResult run_segment(const Body& body, const std::vector<Centre>& centres, const MethodInfo& m, const Advance& how,
                       const Options& options) {
  return in_direction(body, how, options, [&](const Body& b, const Advance& a, const Options& o) {
    return run_estimated(b, centres, m, a, o);
  });
}

}  // namespace

void check_request(const Scene& scene, const MethodInfo* method, const Advance& how, const Options& options) {
  validate(scene);
  detail::check_run(scene.centres, method, how, options);
}

void detail::check_run(const std::vector<Centre>& centres, const MethodInfo* method, const Advance& how,
                       const Options& options) {
  if (const auto* f = std::get_if<FictitiousSteps>(&how); f && f->end.index() == 0 && f->ds < 0.0)
    throw Error("the fictitious step ds must be > 0 (a run backwards has a negative end time), got " + fmt(f->ds));
  check(forwards(how));  // a run backwards is checked as the forward run it makes (integrate_estimated)
  if (const auto* accuracy = std::get_if<Accuracy>(&how)) {
    check_tolerance(accuracy->tol);
    if (method) adaptive::check_searchable(*method);
  } else if (!method) {
    throw Error("only the accuracy mode chooses a method by itself; name one");
  } else {
    check_takes(*method, how);
  }
  check(options);
  check_energy_bound(options.max_energy_error);
  check_error_bound(options.max_error);
  detail::validate_events(options.events, centres);
}

void check_time_step_constant(double omega_c, const MethodInfo* method, bool accuracy) {
  require_non_negative(omega_c, "the time-step constant omega_c");
  if (accuracy) throw Error("the accuracy mode chooses the time-step constant omega_c itself: do not give it");
  if (method && !takes_time_step_constant(*method))
    throw Error("the time-step constant omega_c is for the time-transformed methods (logh-*, ttl-*); " + method->name +
                " does not take it");
}

BodyResult detail::integrate_checked(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                                     const Advance& how, const Options& options) {
  return integrate_estimated(body, centres, method, how, options);
}

BodyResult integrate_body(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                          const Advance& how, const Options& options) {
  check_request(Scene{centres, {body}}, method, how, options);
  return integrate_estimated(body, centres, method, how, options);
}

Result integrate(const Scene& scene, const MethodInfo* method, const Advance& how, const Options& options) {
  check_request(scene, method, how, options);
  Result all;
  for (const Body& body : scene.bodies) {
    BodyResult b = integrate_estimated(body, scene.centres, method, how, options);
    all.force_evals += b.total_force_evals();
    all.wall_s += (b.accuracy ? b.accuracy->wall_s : b.run.wall_s) + b.error.wall_s;
    if (all.outcome == Outcome::ok && b.outcome != Outcome::ok) {
      all.outcome = b.outcome;
      all.reason = (body.name.empty() ? std::string("body") : body.name) + ": " + b.reason;
    }
    all.bodies.push_back(std::move(b));
  }
  return all;
}

Result integrate(const Scene& scene, std::string_view method, const Advance& how, const Options& options) {
  const bool automatic = method == "auto";
  if (automatic && !std::holds_alternative<Accuracy>(how))
    throw Error("method auto needs the accuracy mode (Accuracy: the tolerance to deliver)");
  return integrate(scene, automatic ? nullptr : &method_or_throw(method), how, options);
}

bool searches(const MethodInfo* method, const StepRequest& request) {
  return !method || (request.tol && !takes_tolerance_per_step(*method));
}

StepRequest with_default_end(StepRequest r, const MethodInfo* method) {
  if (r.t_end || r.steps) return r;
  if (searches(method, r)) r.t_end = kDefaultStep * static_cast<double>(kDefaultSteps);
  else r.steps = kDefaultSteps;
  return r;
}

Advance advance_for(const MethodInfo* m, const StepRequest& r) {
  if (r.t_end && r.steps) throw Error("give a number of steps or an end time t_end, not both");
  if (r.t_end && !std::isfinite(*r.t_end)) require_positive(*r.t_end, "the end time t_end");  // -inf named as given
  if (searches(m, r)) {
    if (!r.tol) throw Error("method auto needs the accuracy to deliver, tol");
    if (r.h || r.steps) throw Error("the accuracy mode (tol) chooses the step: give the end time t_end, not h or steps");
    if (!r.t_end) throw Error("the accuracy mode (tol) needs the end time t_end");
    return Accuracy{*r.tol, r.backward ? -std::abs(*r.t_end) : *r.t_end, r.dt_out};
  }
  if (!r.t_end && !r.steps) throw Error("give an end time t_end or a number of steps");
  const double h = require_positive(r.h.value_or(kDefaultStep), is_time_transformed(*m) ? "the fictitious step ds (h)" : "the step h");
  // Backwards in time: a negative end time, or `backward` with a count of steps; planned forwards.
  const bool back = r.backward || (r.t_end && *r.t_end < 0.0);
  if (back && r.code_loop) throw Error("the thesis code's loop runs forwards only: give a positive end time");
  const std::optional<double> end = r.t_end ? std::optional<double>(std::abs(*r.t_end)) : std::nullopt;
  if (!end) require_count(*r.steps, "the number of steps");
  Advance how = advance_of(*m, {h, end.value_or(0.0), r.steps.value_or(0), r.tol.value_or(kDefaultStepTolerance), r.dt_out});
  if (auto* f = std::get_if<FixedSteps>(&how); f && r.code_loop) {  // the thesis's loop: its own grid
    *f = thesis_code_steps(h, r.steps.value_or(0), end.value_or(0.0));
    f->dt_out = r.dt_out;
  }
  return back ? backwards(how) : how;
}

// --- Stepper ---

namespace {

/// A stepper asked for a tolerance at or below this has a draw of the rounding beside its companion: a chain's
/// error can fall a decade below the tolerance (a leg back cancelling the way out's), where the companion pair
/// alone can agree by chance (rk4 at tol 1e-10 forwards and back on a spinning pass: 4.7e-11 off, read 1.4e-11).
constexpr double kDrawTolerance = 10.0 * bodypoint::kProbeBelowTol;

/// A Stepper's segment of `span` (> 0) forwards: the step, fictitious step or tolerance per step it
/// was built with.
Advance segment_of(const MethodInfo& method, double step, double span) { return advance_to(method, step, span); }

/// A Stepper's request (its scene, its way of advancing time, its options), checked once, when it is
/// built: a segment (advance_to) is valid by construction and runs unchecked.
const MethodInfo& checked_request(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres,
                                  double step, const Options& options) {
  require_positive(step, step_quantity(method));
  check_request(Scene{centres, {body}}, &method, segment_of(method, step, 1.0), options);
  return method;
}

}  // namespace

Stepper::Stepper(const MethodInfo& method, Body body, std::vector<Centre> centres, double step, Options options)
    : Stepper(Checked{}, checked_request(method, body, centres, step, options), body, centres, step, options) {}

Stepper::Stepper(Checked, const MethodInfo& method, const Body& body, const std::vector<Centre>& centres, double step,
                 Options options)
    : method_(&method), body_(body), centres_(centres), step_(step), options_(std::move(options)),
      refusal_(refusal(method, body, centres)) {
  // The time-step constant of a time-transformed method is fixed once, from the starting state, so
  // that every segment integrates the same transformed system.
  if (takes_time_step_constant(method) && options_.omega_c < 0.0)
    options_.omega_c = automatic_omega_c(body_, centres_, step_);
  // A segment has no error estimate of its own (a companion per segment would compare segments that
  // start from one state, not the runs).
  options_.estimate_error = false;
  // A departure through the start's distance is the stepper's start, not each segment's (the events
  // were checked with the request).
  options_.events = detail::resolved(options_.events, body_.p, centres_, body_.s0);
  twin_.none = "none: a stepper given a step has no error estimate (one that asks for a tolerance has)";
}

Advance Stepper::segment(double span) const { return segment_of(*method_, step_, span); }

Stepper::Stepper(std::string_view method, Body body, std::vector<Centre> centres, double step, Options options)
    : Stepper(method_or_throw(method), std::move(body), std::move(centres), step, options) {}

namespace {

/// The accuracy mode's delivered run for a Stepper built with a tolerance: method, step and time-step
/// constant searched over the whole span (no sink, no events: the segments hand those on).
BodyResult searched(std::string_view method, const Body& body, const std::vector<Centre>& centres, const Accuracy& a,
                    Options options) {
  const MethodInfo* m = method == "auto" ? nullptr : &method_or_throw(method);
  check_request(Scene{centres, {body}}, m, Accuracy{a.tol, a.t_end}, options);  // the Stepper's one check
  options.sink = nullptr;
  options.events.clear();
  BodyResult r = detail::integrate_checked(body, centres, m, Accuracy{a.tol, a.t_end}, options);
  if (r.outcome != Outcome::ok || !r.accuracy)
    throw Error("the accuracy mode found no step for tol " + fmt(a.tol) + " to t_end = " + fmt(a.t_end) + ": " + r.reason);
  return r;
}

Options with_constant(Options o, const BodyResult& r) {
  if (takes_time_step_constant(*r.method)) o.omega_c = r.accuracy->omega_c;
  return o;
}

}  // namespace

Stepper::Stepper(std::string_view method, Body body, std::vector<Centre> centres, const Accuracy& a, Options options)
    : Stepper(body, centres, searched(method, body, centres, a, options), options, a.t_end) {
  asked_ = method;
}

Stepper::Stepper(const Body& body, const std::vector<Centre>& centres, const BodyResult& r, const Options& options,
                 double t_end)
    : Stepper(Checked{}, *r.method, body, centres, r.accuracy->h_chosen, with_constant(options, r)) {
  searched_ = r.accuracy;
  accuracy_ = r.accuracy;
  accuracy_t_end_ = t_end;
  twin_.s = body.s0;
  if (r.accuracy->tol <= kDrawTolerance) twin_.draw = detail::start_moved_by_rounding(body.s0, detail::rounding_way(1));
  if (!options.estimate_error) {
    twin_.none = "none: the error estimate is off (Options::estimate_error)";
    return;
  }
  if (const auto c = detail::segment_companion(*method_, body_, segment(1.0), 1, twin_.none)) {
    twin_.none.clear();
    twin_.factor = c->factor;
    twin_.basis = c->basis;
  }
}

ErrorEstimate Stepper::error() const {
  ErrorEstimate e;
  e.force_evals = twin_.force_evals;
  if (!carries_error()) {
    e.basis = twin_.none;
    return e;
  }
  e.value = twin_.factor * bodypoint::state_distance(body_.s0, twin_.s);
  e.basis = twin_.basis + ", beside every segment and write (the chain's error at t = " + fmt(t_) + ")";
  if (twin_.draw && detail::at_rounding_level(e)) {
    const double pair = e.value;
    detail::add_rounding_spread(e, body_.s0, *twin_.draw, 0, 0.0, detail::kRepeatRoundingDraw);
    detail::bound_from_draws(e, pair);
  }
  return e;
}

State Stepper::error_state() const {
  State e;
  if (!carries_error()) return e;
  e.R = twin_.factor * (body_.s0.R - twin_.s.R);
  e.v = twin_.factor * (body_.s0.v - twin_.s.v);
  e.w = twin_.factor * (body_.s0.w - twin_.s.w);
  return e;
}

void Stepper::carry_error(const State& e) {
  if (!carries_error())
    throw Error("this stepper has no companion to carry an error in (" + twin_.none + "): ask for a tolerance");
  if (!is_finite(e)) throw Error("the error carried in must be finite");
  // error_state() is the difference times the factor: the companion goes where its difference is e over it, as
  // the same chain in one stepper would have it (a leg back whose error cancels the way out's is then read as
  // that: rk4 at tol 1e-8 out to 30 and back as two steppers, 3.6e-11 off, read 2.0e-10 with e placed whole).
  twin_.s.R = body_.s0.R - e.R / twin_.factor;
  twin_.s.v = body_.s0.v - e.v / twin_.factor;
  twin_.s.w = body_.s0.w - e.w / twin_.factor;
  report_chain();
}

void Stepper::report_chain() {
  if (!searched_) return;
  accuracy_ = searched_;
  const ErrorEstimate e = error();
  if (steps_ == 0 && twin_.force_evals == 0 && e.value == 0.0) return;  // nothing run or carried yet: the search's
  accuracy_->err_estimate = e.value;
  accuracy_->basis = "the chain's error at t = " + fmt(t_) + ": " + e.basis + "; the search: " + searched_->basis;
}

bool Stepper::advance_companion(double t1, long run_steps, std::string& broke) {
  if (!carries_error() || t1 == t_) return true;
  const Advance fwd = segment(std::abs(t1 - t_));
  Options o = options_;
  o.sink = nullptr;
  o.events.clear();
  o.track_invariants = false;  // the run's flags judge the run; the companion only has to get through
  o.carried = twin_.carried;
  Body b = body_;
  b.s0 = twin_.s;
  for (int level = 1; level <= detail::kMaxCompanionLevels; ++level) {
    std::string none;
    const auto c = detail::segment_companion(*method_, b, fwd, level, none);
    if (!c) {
      twin_.none = "none from t = " + fmt(t_) + ": " + none;
      return true;
    }
    if (level == 1) twin_.factor = c->factor, twin_.basis = c->basis;  // the method may be new (a write planned anew)
    const BodyResult x = run_segment(b, centres_, *method_, t1 < t_ ? backwards(c->how) : c->how, o);
    twin_.force_evals += x.run.force_evals;
    if (x.outcome == Outcome::failed && x.reason == kStoppedOnRequest) return false;
    if (detail::companion_broke_down(x) || x.outcome == Outcome::refused) {
      broke = "the " + c->basis + " broke down between t = " + fmt(t_) + " and " + fmt(t1) + " (" +
              (x.reason.empty() ? std::string(outcome_name(x.outcome)) : x.reason) + ")";
      twin_.none = "none: " + broke;
      return true;
    }
    if (detail::companion_refines(fwd, run_steps, x.run.steps) || level == detail::kMaxCompanionLevels) {
      twin_.s = x.run.final;
      twin_.carried = x.run.carried;
      break;
    }
  }
  if (!twin_.draw) return true;
  // The draw of the rounding: the segment's own steps off its grid (a repeat, not a finer run).
  b.s0 = *twin_.draw;
  o.carried = twin_.draw_carried;
  const BodyResult y = run_segment(b, centres_, *method_, t1 < t_ ? backwards(detail::off_grid(fwd)) : detail::off_grid(fwd), o);
  twin_.force_evals += y.run.force_evals;
  if (y.outcome == Outcome::failed && y.reason == kStoppedOnRequest) return false;
  twin_.draw = y.run.final;  // a draw that broke down is not finite: add_rounding_spread leaves it out
  twin_.draw_carried = y.run.carried;
  return true;
}

void Stepper::set_state(const State& s) { set_state(s, t_); }

void Stepper::apply(const std::function<State(const State&)>& write_state) {
  const State s = write_state(body_.s0);
  if (!carries_error()) return set_state(s);
  const State c = write_state(twin_.s);
  set_state(s, t_, c);
}

namespace {

/// A written vector within this relative distance of a multiple of the one it replaced was scaled (written_over).
constexpr double kScaledWrite = 1e-12;

/// A write that changes none of the scene's time scales by more than this share keeps the plan (a small kick
/// or correction, written every segment, would otherwise pay a search each time).
constexpr double kReplanScaleChange = 0.1;

/// Whether the state `to` written over `from` moves a time scale of the step's: the spin's rate (B/D)|K1|,
/// the speed, or the distance to the nearest centre, by more than kReplanScaleChange.
bool moves_time_scales(const Body& body, const State& to, const std::vector<Centre>& centres) {
  const auto moved = [](double a, double b) { return std::abs(a - b) > kReplanScaleChange * std::max(std::abs(a), std::abs(b)); };
  const State& from = body.s0;
  return moved(to_momenta(body.p, from).K1.norm(), to_momenta(body.p, to).K1.norm()) || moved(from.v.norm(), to.v.norm()) ||
         moved(nearest_distance(centres, from.R), nearest_distance(centres, to.R));
}

/// The companion's state after a write that took the stepper's state from `from` to `to`, each vector as the
/// write moved the stepper's: a vector scaled by a number (w = -w, a speed halved) is scaled alike, so that the
/// error it carried turns with it; any other is moved by the same change (a kick). (A write w = -w taken as a
/// change left the companion's w error unturned: on table 3.1 at tol 1e-8, read 3e-8 for 8e-7.)
Vec3 written_vector(const Vec3& twin, const Vec3& from, const Vec3& to) {
  if (to == from) return twin;
  const double n = from.squaredNorm();
  if (n > 0.0) {
    const double c = from.dot(to) / n;
    if ((to - c * from).norm() <= kScaledWrite * to.norm()) return c * twin;
  }
  return twin + (to - from);
}

State written_over(const State& twin, const State& from, const State& to) {
  return State{written_vector(twin.R, from.R, to.R), written_vector(twin.v, from.v, to.v), written_vector(twin.w, from.w, to.w)};
}

}  // namespace

void Stepper::set_state(const State& s, double t, const State& companion) { write(s, t, &companion); }

void Stepper::set_state(const State& s, double t) { write(s, t, nullptr); }

void Stepper::write(const State& s, double t, const State* companion) {
  if (!std::isfinite(t)) throw Error("the stepper's time must be a finite number, got " + fmt(t));
  if (companion && !carries_error())
    throw Error("this stepper has no companion to write (" + twin_.none + "): ask for a tolerance");
  if (companion && !is_finite(*companion)) throw Error("the companion's state written must be finite");
  Body b = body_;
  b.s0 = s;
  validate(Scene{centres_, {b}});
  if (accuracy_ && moves_time_scales(body_, b.s0, centres_)) {  // plan anew: to t_end, or the whole span again past it
    const double left = accuracy_t_end_ - t;
    const double span = left != 0.0 && (left > 0.0) == (accuracy_t_end_ > 0.0) ? left : accuracy_t_end_;
    Options o = options_;
    o.omega_c = -1.0;
    const BodyResult r = searched(asked_, b, centres_, Accuracy{accuracy_->tol, span}, o);
    method_ = r.method;
    step_ = r.accuracy->h_chosen;
    options_.omega_c = takes_time_step_constant(*method_) ? r.accuracy->omega_c : -1.0;
    searched_ = r.accuracy;
    searched_->basis += "; searched again from the state set at t = " + fmt(t);
    accuracy_t_end_ = t + span;
  }
  twin_.s = companion ? *companion : written_over(twin_.s, body_.s0, b.s0);
  twin_.carried = std::numeric_limits<double>::quiet_NaN();
  if (twin_.draw) twin_.draw = written_over(*twin_.draw, body_.s0, b.s0), twin_.draw_carried = twin_.carried;
  body_ = std::move(b);
  t_ = t;
  stopped_ = false;
  carried_ = std::numeric_limits<double>::quiet_NaN();  // the new state's own energy shell
  report_chain();
}

Outcome Stepper::advance_to(double t) {
  if (!(std::isfinite(t) && t != t_))
    throw Error("advance_to needs a finite time other than the current one (" + fmt(t_) + "), got " + fmt(t));
  // A segment starts where the last one ended; a state that is no longer a motion (the last segment
  // diverged) is not run on, nor a scene the method refuses (asked once, at construction).
  if (!refusal_.empty() || !is_finite(body_.s0)) {
    reason_ = !refusal_.empty() ? refusal_
                                : "the stepper's state is not finite (" +
                                      (reason_.empty() ? std::string("a segment diverged") : reason_) + "): set_state() a new one";
    return Outcome::refused;
  }
  const double span = std::abs(t - t_);  // before t_: backwards in time (in_direction, is_backward)
  Advance how = segment(span);
  if (t < t_) how = backwards(how);
  // Samples carry absolute times (the segment's run starts at 0); a later segment's first sample is
  // the state the previous one ended with, already handed on.
  const double t0 = t_;
  const bool first = steps_ == 0;
  SampleSink shifted;
  Options opt = options_;
  opt.carried = carried_;  // the time transformation goes on where the last segment left it
  if (options_.sink) {
    shifted = [this, t0, first](const Sample& s) {
      if (s.step == 0 && !first) return;
      (*options_.sink)(Sample{s.step, t0 + s.t, s.s, s.rel_dE, s.rel_dK2sq, s.abs_dK2Q, s.inside});
    };
    opt.sink = &shifted;
  }
  const BodyResult r = run_segment(body_, centres_, *method_, how, opt);  // resolved and checked in the constructor
  if (!ran(r.outcome)) {
    reason_ = r.reason;
    return r.outcome;
  }
  const double t1 = r.run.stopped ? t0 + r.run.t_end : t;
  std::string broke;
  if (!advance_companion(t1, r.run.steps, broke)) {  // stopped on request: the segment is not kept
    reason_ = kStoppedOnRequest;
    return Outcome::failed;
  }
  for (EventHit h : r.events) {
    h.t += t0;
    events_.push_back(h);
  }
  detail::keep_closest(events_, options_.events);  // the closest approach so far
  body_.s0 = r.run.final;
  carried_ = r.run.stopped ? std::numeric_limits<double>::quiet_NaN() : r.run.carried;  // a cut state is not the run's end
  stopped_ = r.run.stopped;
  t_ = t1;
  force_evals_ += r.run.force_evals;
  steps_ += r.run.steps;
  if (r.outcome != Outcome::ok) reason_ = r.reason;
  report_chain();
  if (!broke.empty() && (r.outcome == Outcome::ok || r.outcome == Outcome::inaccurate)) {
    reason_ = broke + ": a finer step did not get through the scene, so this step does not resolve it and its error is unknown";
    return Outcome::unresolved;
  }
  return r.outcome;
}

}  // namespace bodypoint
