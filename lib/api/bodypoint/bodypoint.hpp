// bodypoint: the public API. One header for a program that integrates body-points:
//
//   #include <bodypoint/bodypoint.hpp>
//   bodypoint::Scene scene = bodypoint::thesis_scene({});                 // table 3.1 of the thesis
//   bodypoint::Result r = bodypoint::integrate(scene, "lp-y4", bodypoint::FixedSteps{1e-3, 50000});
//   if (r.outcome == bodypoint::Outcome::ok) use(r.bodies[0].run.final);    // R, v, w at t = 50
//
// What it holds, from the ground up:
//   - the model (model.hpp): a Scene is fixed Coulomb centres and independent body-points, each with
//     its parameters m, B, J and initial state (R, v, w); thesis_scene() builds the thesis's set-up;
//     read_scene_file() reads a TOML scene (scene_file.hpp); its first integrals (energy,
//     kinetic_energy, ...) are in <bodypoint/invariants.hpp>, included where needed so that a
//     program's objects do not depend on the force kernel. The physics and the meaning of every
//     parameter are in docs/physics.md.
//   - the catalogue (methods.hpp): every method, each a MethodInfo row with its family, order and
//     cost; methods(), find_method(), and choose_method() for `auto`.
//   - a way of advancing time, as a value (Advance): FixedSteps, FictitiousSteps (time-transformed
//     and regularised methods), ControlledSteps (step-size-controlled peers) or Accuracy (a relative
//     error of the final state to deliver; the step is searched); advance_for() makes the right one
//     from a step, an end and a tolerance, as the command line and the Python module take them.
//   - what a run observes (Options): invariants, samples to a sink (which may end the run by
//     returning Flow::stop), events, the bound of the accuracy flag.
//   - integrate(): every body of a scene with one method and one Advance; a Result per body with a
//     typed Outcome (ok, diverged, unresolved, inaccurate, collision, incomplete, refused, failed) and its
//     one-line reason; a negative end time runs backwards (time reversal).
//   - events (Event): closest approaches, radii and planes crossed, located to round-off on the
//     method's own steps; scattering.hpp turns a run into an encounter's observables (deflection,
//     asymptotes, impact parameter, spin turn).
//   - Stepper: one body advanced segment by segment (advance_to, either way in time), queried and
//     continued; built with a step or with a tolerance (the accuracy mode's method and step).
//   - <bodypoint/record.hpp>: a run's results as named fields (JSON, CSV rows), as the command line
//     and the Python module write them; RunOptions::cancel stops a run from another thread.
//
// Invalid input (a scene that breaks a rule of validate(), a step that is not a finite number > 0, an
// unknown method name) throws bodypoint::Error with a one-line reason naming the quantity; anything
// that happens to a valid request is reported in the Result, never thrown.
#pragma once

#include "bodypoint/methods.hpp"
#include "bodypoint/model.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/scattering.hpp"
#include "bodypoint/scene_file.hpp"

#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace bodypoint {

/// Something to locate along a run: where a function g of the state changes sign. It is found on the
/// method's own steps: the step that brackets the change is taken again from its start with shorter
/// steps tau of the same method (the same time-step constant, tolerance or fictitious step), and tau
/// is solved for g = 0 to round-off (Illinois regula falsi). So every family, fixed-step,
/// time-transformed, regularised and step-size-controlled, serves as its own dense output.
struct Event {
  enum class Kind {
    /// The run's closest approach to a centre: the smallest of the local minima of |R - c| (a spinning
    /// body's helix makes several). Only that one is reported. As a stop, it is known only at the run's
    /// end: the run goes on to its end time and is cut at that least distance (states after it are not
    /// handed on).
    closest_approach,
    local_minimum,  ///< every local minimum of |R - c| (g = (R - c).v turns from < 0 to >= 0)
    radius,         ///< |R - c| crosses `value`, either way
    plane,          ///< normal.R crosses `value`, either way
    /// The guiding centre G = R + K1 x K2/|K1|^2 (B = 0: the body) crosses the distance `value` from
    /// the centre outward; value 0: its distance at the start of the run (the encounter has ended).
    departure,
    arrival,  ///< G crosses the distance `value` > 0 from the centre inward
  };
  Kind kind = Kind::closest_approach;
  std::size_t centre = 0;  ///< every kind but plane: which of the scene's centres
  double value = 0.0;      ///< radius, departure, arrival: the distance; plane: the offset
  Vec3 normal = Vec3::UnitX();
  /// The run ends at this event's first hit: the state there is the run's final state (RunResult::
  /// stopped, t_end its time) and the last of BodyResult::events. A fixed-step, time-transformed or
  /// step-size-controlled run stops stepping on the step that crosses it; the accuracy mode searches
  /// its step to twice the stop's time where the span asked for is much longer (a pilot run finds where
  /// it falls), and delivers the run cut at the event.
  bool stop = false;
  /// departure, arrival: the guiding centre's distance from this point instead of from the centre `centre`
  /// (an encounter with several centres measures it from their far-field centre, far_field_centre).
  std::optional<Vec3> about = std::nullopt;
  /// "closest", "local-min(1)", "r=5", "plane(1,0,0)=0", "departure": for outputs and messages.
  [[nodiscard]] std::string label() const;
};

/// An event from its text, the one grammar of the command line, scene tools and Python:
///   closest, closest:K        the closest approach (to centre K)
///   local-min, local-min:K    every local minimum of the distance
///   r=V, r:K=V                the distance crosses V
///   x=X, y=Y, z=Z, plane=nx,ny,nz,offset
///   departure, departure=V, departure:K=V   the guiding centre leaves through V (the start distance)
///   arrival=V, arrival:K=V    the guiding centre comes in through V
/// Throws Error with the text and what is wrong with it.
Event parse_event(std::string_view text);

/// One located event.
struct EventHit {
  std::size_t event = 0;  ///< index into Options::events
  double t = 0.0;
  State s;
  double r = 0.0;  ///< |R - c| to the event's centre (plane: to the scene's first centre); "r" in JSON and Python too
  /// The estimated errors of t, r and the state (relative, as the run's err_estimate) from the same events
  /// located on a companion run (estimate/events.cpp); NaN where not known (no estimate of the run, a
  /// step-size-controlled method, a companion that hit the event another number of times, a Stepper's
  /// segment).
  double t_error = std::numeric_limits<double>::quiet_NaN();
  double r_error = std::numeric_limits<double>::quiet_NaN();
  double state_error = std::numeric_limits<double>::quiet_NaN();
};

/// Every centre's closest approach (Kind::closest_approach for centres 0 .. n-1), as events.
std::vector<Event> closest_approaches(std::size_t centres);
/// The nearest of the closest-approach hits among `hits` (`events`: the Options::events they index);
/// a hit with a finite distance before one without. nullptr when there is none.
const EventHit* nearest_approach(const std::vector<EventHit>& hits, const std::vector<Event>& events);

/// The default bound on the estimated relative error of a run called ok (Options::max_error): 1 %, as
/// the energy's (kDefaultMaxEnergyError).
inline constexpr double kDefaultMaxError = 1e-2;


/// What a run asks for besides the way of advancing time and what it observes (RunOptions: invariants,
/// samples, the time-step constant c): events to locate and the bound of the accuracy flag.
struct Options : RunOptions {
  /// Located along the run (BodyResult::events); the run then observes every step (or every dt_out).
  std::vector<Event> events;
  /// A run whose relative energy error exceeds this bound ends Outcome::inaccurate (> 0; infinity: no
  /// bound). Not applied where E is not conserved (the thesis code's force law).
  double max_energy_error = kDefaultMaxEnergyError;
  /// Estimate the error of a run asked for by step with a companion run (ErrorEstimate; it costs about
  /// half the run). Off: BodyResult::error says the run has none. The accuracy mode always has one.
  bool estimate_error = true;
  /// Estimate the located events' errors (EventHit::t_error, r_error, state_error) with one companion run
  /// at twice the step that locates them too (about half the run); off, or without estimate_error: NaN.
  bool estimate_events = true;
  /// A run whose estimated relative error (BodyResult::error) exceeds this bound ends Outcome::inaccurate
  /// (> 0; infinity: no bound).
  double max_error = kDefaultMaxError;
};

/// How good a run's final state is: an a-posteriori estimate of its relative error,
///   err = max(|R - R_exact|/|R_exact|, |v - v_exact|/|v_exact|)   (the accuracy mode's measure, tol),
/// or, when the run has none, why. A run by step is compared with a companion run of the same method
/// to the same end (the same stop event, the same time-step constant c), by Richardson's principle
/// (Hairer, Norsett, Wanner, Solving ODEs I, sec. II.4): first a coarse companion at up to twice the
/// step (fixed and fictitious steps) from the start moved by a rounding; in the asymptotic regime it
/// differs from the run by the run's error times r^p - 1 (the order taken as at most 4, at most 2 for
/// a ratio r below 2), and it costs half a run. Where that pair cannot be trusted (the run flagged, the
/// coarse steps beyond the flags or its energy, an estimate above 1e-5, too few steps) a fine companion
/// at half the step decides, or at a tenth of the tolerance per step (step-size-controlled methods):
/// its error is 2^-p of the run's, so the run's error is their difference over 1 - 2^-p. Where
/// round-off dominates, the estimate is at least the pair's difference up to the rounding level 1e-10,
/// unless a second coarse run shows the pair's order (then the difference is the truncation's).
/// The accuracy mode's estimate is its search's (adaptive/tolerance.hpp).
struct ErrorEstimate {
  /// The fine companion of a run by step runs at the step over this ratio (it costs that many runs),
  /// the coarse one at up to this ratio times the step.
  static constexpr double kStepRatio = 2.0;
  /// What an estimate costs in runs where its coarse companion is trusted (the fine one costs
  /// kStepRatio runs more): budgets count this.
  static constexpr double kTypicalCost = 1.0 / kStepRatio;
  /// Draws of the rounding where the estimate is at the scene's rounding level (below 1e-10): the
  /// companion's and this many less one more from the start moved the other way (a fixed-step coarse
  /// companion's twin, its own steps, a second vector lane beside it where the method has a batch kernel;
  /// otherwise runs off the run's grid, a coarse one half a run), a bound rather than a value: a coarse
  /// draw measured from the coarse run and summed with the pair's difference (which holds the run's and the
  /// coarse run's roundings: three draws), a repeat of the run measured from the run and its part taken
  /// kRoundingBound times. Under independent draws the estimate is more than 3x below the error 1 in 10
  /// times with one draw, 1 in 150 with two, 1 in 3,400 with three. bench/estimate_ladder.py, estimates
  /// more than 3x below an error above 1e-12 at this level: 1 with one draw, 1 with two, 0 as now
  /// (2,708 runs; `--unseen` 1,153: 0).
  static constexpr int kRoundingDraws = 2;
  static constexpr double kRoundingBound = 2.0;
  double value = std::numeric_limits<double>::quiet_NaN();  ///< the estimate; NaN when the run has none
  std::string basis;       ///< how it was obtained ("companion run at 2h ..., order 4"), or why there is none
  /// What the companions whose states it used cost (the accuracy mode: counted in its search). A
  /// companion's twin run beside it in a vector lane and not needed (above the rounding level) is not
  /// counted: it takes no time of its own, and a sweep's batches, which run twins only where wanted, count
  /// the same.
  long force_evals = 0;
  double wall_s = 0.0;
  /// Where the run was flagged unresolved: a second companion one level finer showed the error falling
  /// as the step's order says, so the estimate may overrule the flag (the accuracy mode: always).
  bool confirmed = false;
  /// The estimate of what an encounter's observables read from the final state, the guiding centre's
  /// orbit (its position and K1) without the helix's phase, where it differs from `value`: a run whose far
  /// field was crossed by legs of one turn of the spin a step knows the phase along its path less well
  /// than the orbit. NaN: `value`.
  double orbit = std::numeric_limits<double>::quiet_NaN();
  /// The pair of states the estimate compared: the run's and its companion's at the end of the span they
  /// were compared over (the accuracy mode's: its search's end, before a stop event cut the run), with their
  /// times. In the asymptotic regime every smooth quantity read from a final state and its time errs by the
  /// same multiple of what the pair differs by in it (the events' rule, estimate/events.cpp): quantity().
  struct Pair {
    State run, companion;
    double t_run = 0.0, t_companion = 0.0;
  };
  std::optional<Pair> pair;
  /// An encounter's time delay's error as the run read it, where the run computed it itself (far legs:
  /// the legs' and the run's between them); NaN: from `pair` (Encounter::time_delay_error).
  double time_delay = std::numeric_limits<double>::quiet_NaN();
  /// Far legs: their part of the error of a closest approach's distance (the largest over the run's), which each
  /// EventHit::r_error adds where the location's is known (0 without legs, NaN where not known; an encounter's run
  /// from 2L locates without errors, and the limit takes this part from here).
  double closest_from_legs = 0.0;
  /// The error of a quantity read as x_run from pair->run and x_companion from pair->companion: what they
  /// differ by times what the estimate makes of the pair's distance, times kQuantityMargin, at least
  /// `rounding`; NaN without a pair or where the pair is at one state (nothing to scale).
  /// The margin: the scaling is exact only where every quantity errs by one multiple of the pair's difference;
  /// an encounter's time delay read so from accuracy-mode runs of made-up scenes (TOL 1e-5 .. 1e-8, no far legs)
  /// was 0.90-1.05 of its distance from a run at 1e-11 (median 1.03), and 1.5 keeps it at most 2x above.
  static constexpr double kQuantityMargin = 1.5;
  [[nodiscard]] double quantity(double x_run, double x_companion, double rounding) const;
  [[nodiscard]] bool known() const { return !std::isnan(value); }
  [[nodiscard]] double for_orbit() const { return std::isnan(orbit) ? value : orbit; }
};

/// What the accuracy mode did to deliver its tolerance (Accuracy).
struct AccuracyReport {
  double tol = 0.0;
  double err_estimate = 0.0;  ///< estimated relative error of the final state
  double h_chosen = 0.0;      ///< the step chosen: h, or the fictitious step ds of time-transformed methods (JSON, CSV, Python: h_chosen)
  double omega_c = 0.0;       ///< time-transformed methods: the time-step constant c used
  int runs = 0;               ///< integrations made in all, the delivered run (BodyResult::run) included
  long force_evals = 0;       ///< over all of them
  double wall_s = 0.0;        ///< their step loops
  std::string basis;          ///< what err_estimate is (Richardson over the search's runs, or a pair's difference)
};

/// One body's run.
struct BodyResult {
  /// The method that ran (Accuracy with no method: chosen per body); nullptr only when the accuracy
  /// mode refused the scene before a method was chosen.
  const MethodInfo* method = nullptr;
  std::string chosen;                  ///< what was chosen and why (automatic choice only)
  Outcome outcome = Outcome::ok;
  std::string reason;                  ///< one line; empty when ok
  RunResult run;                       ///< final state, steps, cost, invariants (unless refused or failed)
  std::optional<AccuracyReport> accuracy;
  ErrorEstimate error;                 ///< the run's estimated error, or why it has none
  /// What a heuristic saw but could not judge (a step that turned the spin by more than pi, while the
  /// error estimate says the state is right): reported, not refused.
  std::vector<std::string> warnings;
  std::vector<EventHit> events;  ///< Options::events located, in time order
  long event_force_evals = 0;    ///< spent locating them
  /// Spent on its encounter's start distance (Encounter::start_distance_force_evals), where it was measured.
  long encounter_force_evals = 0;
  /// The force evaluations this body cost in all: the run, the search of the accuracy mode or the error
  /// estimate's companion, the events, the encounter's start distance.
  [[nodiscard]] long total_force_evals() const;
};

/// Every body's run, in the scene's order.
struct Result {
  std::vector<BodyResult> bodies;
  Outcome outcome = Outcome::ok;  ///< ok when every body is ok, else the first body's that is not
  std::string reason;             ///< "<body name>: <reason>" of that body
  long force_evals = 0;           ///< all bodies, searches included
  double wall_s = 0.0;            ///< all bodies' step loops, searches included
};

/// The defaults of a run asked for by step (the thesis's table 3.1: h = 1e-4, n = 500000); a
/// step-size-controlled method's tolerance per step: kDefaultStepTolerance (run.hpp).
inline constexpr double kDefaultStep = 1e-4;
inline constexpr long kDefaultSteps = 500000;

/// A run asked for as the command line and the Python module take it, before the method's kind gives
/// it a meaning (advance_for): a step, an end (an end time or a number of steps, not both), a tolerance.
struct StepRequest {
  std::optional<double> h = std::nullopt;      ///< the step h; ds of a time-transformed method; a controlled method's first trial step
  std::optional<long> steps = std::nullopt;    ///< a number of steps (fictitious steps for time-transformed methods)
  std::optional<double> t_end = std::nullopt;  ///< an end time, landed on exactly
  /// A step-size-controlled method's tolerance per step (default kDefaultStepTolerance); for any other
  /// method, or no method (auto), the accuracy to deliver: the step is then searched (Accuracy).
  std::optional<double> tol = std::nullopt;
  double dt_out = 0.0;          ///< output interval (0: none)
  bool code_loop = false;       ///< count fixed steps as the thesis's code did (thesis_code_steps)
  /// Backwards in time from t = 0 (to -t_end, or `steps` steps back); a negative t_end says it too.
  bool backward = false;
};
/// The one mapping from a step request to a way of advancing time, by the method's kind:
///   accuracy (searches): Accuracy{tol, t_end}; h and steps are refused, t_end is needed;
///   fixed-step: t_end given, the steps of at most h that land on it (fixed_steps_to); otherwise
///     `steps` steps of h; under the thesis code's loop its count (thesis_code_steps);
///   time-transformed: fictitious steps ds = h, to exactly t_end or `steps` of them;
///   step-size-controlled: to t_end (or h steps), first trial step min(h, t_end), tolerance tol.
/// h defaults to kDefaultStep; an end (t_end or steps) is required. Throws Error naming the quantity.
Advance advance_for(const MethodInfo* method, const StepRequest& request);

/// Integrates one body of a scene (the scene's centres act on it) with `method`; with Accuracy,
/// `method` may be nullptr: chosen by choose_method.
BodyResult integrate_body(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                          const Advance& how, const Options& options = {});

/// Integrates every body of the scene. With Accuracy `method` may be nullptr (chosen per body).
Result integrate(const Scene& scene, const MethodInfo* method, const Advance& how, const Options& options = {});
/// The same with the method by name; "auto" with Accuracy chooses per body.
Result integrate(const Scene& scene, std::string_view method, const Advance& how, const Options& options = {});

// --- Encounters ---

/// A body's encounter with a single centre, measured on a run: the observables of scattering.hpp
/// when the encounter finished, and whether it did. An encounter has finished when the guiding
/// centre G (B = 0: the body) recedes from every centre and is at least as far from each as at the
/// start: back at its start distance on the way out (the departure event stops a run there).
struct Encounter {
  Outcome outcome = Outcome::ok;  ///< ok; incomplete when the run ended before the body left
  std::string reason;             ///< of incomplete: where the run ended
  /// The two ends' observables (K1, K2, E, turns: always); asymptotes, deflection, b, v_inf and time
  /// delay only when ok.
  Scattering scattering;
  double r_min = Scattering::kNaN, t_min = Scattering::kNaN;  ///< the closest approach (to any centre)
  double r_min_error = Scattering::kNaN, t_min_error = Scattering::kNaN;  ///< theirs (EventHit's r_error, t_error)
  /// Estimated error of the deflection that the asymptotes' model leaves at the run's distances (the
  /// guiding centre is a Kepler particle only far away): the change of the deflection between the
  /// asymptotes taken at the run's ends and at half the start distance, over 2^p - 1 with p =
  /// 2.7, the slowest fall with the distance measured (docs/physics.md, "Scattering"). 0 for B = 0 (Kepler's asymptotes are exact); NaN when not known (no
  /// asymptotes, or the body never came within half its start distance).
  double asymptote_error = Scattering::kNaN;
  std::string asymptote_basis;  ///< how asymptote_error was obtained, or why it is not known
  /// The same model's error in the incoming asymptote's impact parameter and speed at infinity (b_in and
  /// v_inf_in against their L -> infinity values), estimated the same way; NaN when not known.
  double b_error = Scattering::kNaN, v_inf_error = Scattering::kNaN;
  /// The out-of-plane angle's total error: the run's estimate, this model's part and the start distance's
  /// (formed with deflection_error; NaN when a part is not known).
  double out_of_plane_error = Scattering::kNaN;
  double out_of_plane_model_error = Scattering::kNaN;  ///< its asymptotes' model part, as asymptote_error's
  double out_of_plane_start_error = Scattering::kNaN;  ///< its start distance's part (0 where that part is exact)
  /// The error of the deflection that the start's finite distance L leaves against the limit L -> infinity
  /// of the scene as given (the observables converge as 1/L: 3 |x(L) - x(2L)| from the same scene started
  /// at 2L, the thesis's parameters with L doubled and b, v_inf solved again; a material point too where its
  /// K1 is given, its v_inf moving with L). 0 for a scene file's material point (its hyperbola is that of its
  /// states); NaN when not known.
  double start_distance_error = Scattering::kNaN;
  /// The time delay's error from the run: its estimate carried to the time delay read from the final state
  /// and time (ErrorEstimate::quantity on the estimate's pair; with far legs, theirs and the run's between
  /// them); NaN when the run has no estimate.
  double time_delay_run_error = Scattering::kNaN;
  /// The time delay's total error: the run's part and the start distance's, as start_distance_error's (with
  /// the run from 2L's own run part where the delay is taken to the limit); NaN when a part is not known.
  double time_delay_error = Scattering::kNaN;
  std::string start_distance_basis = "not known: not measured";
  long start_distance_force_evals = 0;  ///< the encounter from twice the start distance cost these (its search included)
  /// The deflection's total error: the run's estimated error (a relative error of the final state, which
  /// bounds the angle of its velocity), the asymptotes' model error and the start distance's; NaN when
  /// any part is not known.
  double deflection_error = Scattering::kNaN;
};

/// One body's encounter with the accuracy mode (tol; method nullptr: auto): the run stops at the
/// departure, by t_end (NaN: encounter_span). A run that is not ok keeps its outcome and reason.
struct EncounterResult {
  BodyResult run;
  Encounter encounter;
  std::vector<Event> events;  ///< the events of the run (encounter_options), which run.events index
};
EncounterResult encounter(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method, double tol,
                          double t_end = Scattering::kNaN, Options options = {});

/// One body advanced in segments: advance_to(t) integrates from the current time to t and may be
/// called again to continue. Each segment starts from the state the previous one ended in, as a run
/// from that state would (a one-step method continues exactly as one long run of the same steps,
/// up to round-off in the merged sub-steps; ab4 restarts its history with RK4).
///   step: fixed-step methods: the largest step <= step that lands on t; time-transformed methods: the
///         fictitious step ds; step-size-controlled methods: the tolerance per step, and the first
///         trial step is min(1e-3, t - time()).
/// A stepper that asks for an accuracy carries its error: a companion run one level finer (h/2, ds/2 with the
/// same time-step constant, a tenth of the tolerance per step) goes beside it from the start through every
/// segment and every write, and error() is what the two differ by (Richardson at the method's order) at
/// time(): the whole chain's error, segments, writes and the way back included. A stepper given a step
/// has none (error() says so). A time before time()
/// integrates backwards (the time-reversed run, is_backward): forwards and back by the same steps, a
/// symmetric splitting returns to its start to round-off. Events: each segment locates its hits at
/// absolute times; the closest approach (Event::closest_approach) is the nearest *so far*, replaced
/// when a later segment comes nearer (after advance_to(28) on table 3.1 it is a helix wiggle at
/// t = 27.571, after advance_to(28.5) the encounter's minimum at t = 28.399).
class Stepper {
 public:
  Stepper(const MethodInfo& method, Body body, std::vector<Centre> centres, double step, Options options = {});
  Stepper(std::string_view method, Body body, std::vector<Centre> centres, double step, Options options = {});
  /// A stepper that asks for an accuracy: the accuracy mode searches `method` ("auto": the method
  /// too) for a.tol over [0, a.t_end] (a negative t_end: backwards), and the segments then advance with
  /// the method, step and time-step constant it delivered; accuracy() reports that search, whose
  /// estimate holds at a.t_end (landing steps on the segments' times only shorten steps). Error when the
  /// search refuses (out of reach, the budget).
  Stepper(std::string_view method, Body body, std::vector<Centre> centres, const Accuracy& a, Options options = {});

  /// Integrates to time t != time() (before it: backwards); returns the outcome of the segment (refused or failed leave the
  /// stepper where it was). Samples handed to options.sink carry absolute times.
  Outcome advance_to(double t);

  [[nodiscard]] double time() const { return t_; }
  [[nodiscard]] const State& state() const { return body_.s0; }
  [[nodiscard]] Momenta momenta() const { return to_momenta(body_.p, body_.s0); }
  [[nodiscard]] const BodyPoint& body_point() const { return body_.p; }
  [[nodiscard]] const MethodInfo& method() const { return *method_; }
  [[nodiscard]] long force_evals() const { return force_evals_; }
  [[nodiscard]] long steps() const { return steps_; }
  [[nodiscard]] const std::string& reason() const { return reason_; }  ///< of the last segment that was not ok
  /// Options::events located so far, at absolute times.
  [[nodiscard]] const std::vector<EventHit>& events() const { return events_; }
  /// True once an event with stop = true ended a segment: time() is the event's, and advance_to
  /// continues from there only when asked again.
  [[nodiscard]] bool stopped() const { return stopped_; }
  /// The flag the next segments poll (RunOptions::cancel; nullptr: none), to stop one from outside.
  void cancel_with(const std::atomic<bool>* flag) { options_.cancel = flag; }
  /// The step of the segments: h, a time-transformed method's ds, a controlled method's tolerance per step.
  [[nodiscard]] double step() const { return step_; }
  /// With a tolerance: the search that chose the method and step; its err_estimate is the search's (at its
  /// t_end) until a segment ran, then error()'s at time(). None for a stepper given a step.
  [[nodiscard]] const std::optional<AccuracyReport>& accuracy() const { return accuracy_; }
  /// The estimated error of the state at time(): the companion's (a stepper that asks for an accuracy,
  /// Options::estimate_error on), a relative error of R and v as a run's (ErrorEstimate); NaN, the basis
  /// saying why, where there is none. Its force_evals are the companion's so far.
  [[nodiscard]] ErrorEstimate error() const;
  /// The estimated error of each component of the state at time() (state() less the true state, estimated);
  /// zero where error() is not known.
  [[nodiscard]] State error_state() const;
  /// Carries an error into the current state (a state that came out of another run with its error_state(), so
  /// that a chain of separate runs reports the chain's error): the companion is put at state() - e. Error
  /// when the stepper has no companion.
  void carry_error(const State& e);
  [[nodiscard]] double accuracy_t_end() const { return accuracy_t_end_; }
  /// Replaces the current state (a kick, a corrected state), checked as a scene's; the time stays
  /// unless given. A stepper given a step keeps it (accuracy() stays empty). One that asks for an accuracy,
  /// when the write moves a time scale of its step (the spin's rate, the speed or the distance to the nearest
  /// centre) by more than 10 %, plans anew from the state written: the search runs again for the span from there to its t_end (the
  /// whole span again once t_end is reached), method, step and accuracy() its new ones (a write w = -w at
  /// the closest approach kept the step chosen for the old spin rate: "a step turned the spin by 3.19 rad").
  /// The companion takes the same write, so that the error the state carried in goes on in error(): each
  /// of R, v, w that the write scaled by a number (w = -w) is scaled alike in the companion, any other moved by
  /// the same change (a kick). A write that is another map is given as one (apply), or with the companion's
  /// state written too. Error, the stepper unchanged, when the search refuses.
  void set_state(const State& s);
  void set_state(const State& s, double t);
  void set_state(const State& s, double t, const State& companion);
  /// A write that is a map of the state (a reflection, a rotation of the spin): applied to the state and to
  /// the companion's, as set_state(write(state()), time(), write(companion_state())).
  void apply(const std::function<State(const State&)>& write);
  /// Whether a companion goes beside the segments (error() can be known).
  [[nodiscard]] bool carries_error() const { return twin_.none.empty(); }
  /// The companion's state at time() (error() is what it differs by from state()); state() where there is none.
  [[nodiscard]] const State& companion_state() const { return twin_.none.empty() ? twin_.s : body_.s0; }

 private:
  /// A segment of `span` (> 0) forwards: the step, fictitious step or tolerance per step it was built with.
  [[nodiscard]] Advance segment(double span) const;
  Stepper(const Body& body, const std::vector<Centre>& centres, const BodyResult& searched, const Options& options,
          double t_end);
  /// A request checked already (by the public constructors, once): the segments' settings from it.
  struct Checked {};
  Stepper(Checked, const MethodInfo& method, const Body& body, const std::vector<Centre>& centres, double step,
          Options options);

  const MethodInfo* method_;
  Body body_;  // body_.s0 is the current state
  std::vector<Centre> centres_;
  double step_;
  Options options_;
  double t_ = 0.0;
  long force_evals_ = 0, steps_ = 0;
  std::string reason_;
  std::string refusal_;  ///< why the method refuses the scene, asked once at construction ("" : it accepts it)
  std::vector<EventHit> events_;
  bool stopped_ = false;
  std::optional<AccuracyReport> accuracy_;
  double accuracy_t_end_ = 0.0;
  double carried_ = std::numeric_limits<double>::quiet_NaN();  ///< RunOptions::carried from the last segment
  std::string asked_;  ///< with a tolerance: the method asked for ("auto" or a name), searched again after a write
  /// The companion beside the segments (error()): its state and carried time transformation, the factor its
  /// difference is taken at (the coarsest level's), its basis, or why there is none (`none` non-empty).
  struct Companion {
    State s;
    double carried = std::numeric_limits<double>::quiet_NaN();
    double factor = 1.0;
    std::string basis, none;
    long force_evals = 0;
    /// With a tolerance near the rounding level: a draw of the rounding beside them, the run's steps off its
    /// grid from the start moved by a rounding (error() below that level takes it in, as a run's estimate does).
    std::optional<State> draw;
    double draw_carried = std::numeric_limits<double>::quiet_NaN();
  };
  Companion twin_;
  std::optional<AccuracyReport> searched_;  ///< the search as it reported (accuracy_ is it with error()'s estimate)
  /// Runs the companion beside the segment the stepper made from t_ to t1 in `run_steps` steps (not yet kept):
  /// false when it was stopped on request (the segment is then not kept); `broke` says why where it broke down.
  bool advance_companion(double t1, long run_steps, std::string& broke);
  /// accuracy_ from searched_ and error() at time().
  void report_chain();
  /// set_state's work: the companion's state written too where given, else as set_state says.
  void write(const State& s, double t, const State* companion);
};

}  // namespace bodypoint
