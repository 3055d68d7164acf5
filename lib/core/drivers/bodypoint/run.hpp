// bodypoint: running one method on one body of a scene (the core layer's interface to every method).
//
// A run is one method, one way of advancing time (Advance: fixed steps, fictitious steps, step-size
// control, or an accuracy that searches one of those) and the observations asked for (RunOptions). The
// Advance is checked once, where its alternatives are defined (check; check_takes in
// detail/run_parts.hpp); the method's driver reads the alternative it takes and nothing else. Invariants are tracked only when asked for, and
// states are handed to a sink only when one is given: with neither, the step loop runs with a null
// observer and stores nothing. This layer lists its own methods (core_methods); the registry of every
// method is one layer up (bodypoint/methods.hpp).
#pragma once

#include "bodypoint/invariant_stats.hpp"
#include "bodypoint/model.hpp"

#include <functional>
#include <atomic>
#include <optional>
#include <string>
#include <string_view>
#include <limits>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace bodypoint {

/// One observed state with the deviations of the integrals the field has.
struct Sample {
  long step;
  double t;
  const State& s;
  double rel_dE, rel_dK2sq, abs_dK2Q;
  /// A state inside step `step` (RunOptions::inside_steps: a collocation point of far-ip's step), not a
  /// step's end; its deviations are those of the last step's end.
  bool inside = false;
};
/// What a sink tells the run after a state: go on, or end the run at that state.
enum class Flow { go, stop };

/// Receives observed states. A callable returning Flow may end the run: after Flow::stop the run
/// returns what it has, that state as final, its step and time, the invariants up to it and the force
/// evaluations made, with RunResult::stopped set (the accuracy mode hands its delivered run's states on
/// after its search: there Flow::stop ends the samples, not the run). A callable returning nothing
/// always goes on.
class SampleSink {
 public:
  SampleSink() = default;
  template <class F>
    requires(!std::is_same_v<std::decay_t<F>, SampleSink> && std::is_invocable_v<F&, const Sample&>)
  SampleSink(F f)  // NOLINT(google-explicit-constructor): a lambda is a sink
      : f_(wrap(std::move(f))) {}
  Flow operator()(const Sample& s) const { return f_(s); }
  explicit operator bool() const { return static_cast<bool>(f_); }

 private:
  template <class F>
  static std::function<Flow(const Sample&)> wrap(F f) {
    if constexpr (std::is_same_v<std::invoke_result_t<F&, const Sample&>, Flow>) {
      return f;
    } else {
      return [g = std::move(f)](const Sample& s) mutable {
        g(s);
        return Flow::go;
      };
    }
  }
  std::function<Flow(const Sample&)> f_;
};

struct RunResult {
  State final;
  long steps = 0;
  double t_end = 0.0;
  long force_evals = 0;
  double wall_s = 0.0;
  std::optional<InvariantStats> invariants;
  double min_step = 0.0, max_step = 0.0;  ///< smallest and largest accepted physical step
  bool stopped = false;  ///< a sink ended the run early (Flow::stop): t_end is where
  /// A time-transformed method's auxiliary variable at the final state (logH: g = E - T, TTL: W), for a
  /// run that goes on from there (RunOptions::carried); NaN for the other methods and a stopped run.
  double carried = std::numeric_limits<double>::quiet_NaN();
};

/// Thesis: the thesis's drift/kick schemes; LiePoisson: exact splittings; Odeint: fixed-step
/// odeint steppers (rk4, ab4); OdeintAdaptive: step-size-controlled odeint steppers (--tol);
/// Gsl: GSL's step-size-controlled steppers (--tol; peers, present when built with GSL);
/// TimeTransformed: fixed fictitious step ds, variable physical step (logh-*, ttl-*);
/// Regularised: the Kustaanheimo-Stiefel flow, exact in its fictitious time (ks);
/// Extrapolated: the logH leapfrog with Bulirsch-Stoer extrapolation and a tolerance per step (logh-bs;
/// a peer, as Mikkola's codes integrate);
/// FarField: Chebyshev-Picard collocation in the interaction picture of the exact drift, a step set by
/// the field's slow scale rather than by the spin (far-ip, far_field.hpp).
enum class Family { Thesis, LiePoisson, KeplerSplit, Odeint, OdeintAdaptive, Gsl, TimeTransformed, Regularised, Extrapolated, FarField, Sundials };

/// The three ways of advancing time, one driver each, and the accuracy mode that searches the step of
/// one of them:
///   FixedSteps       `steps` steps of h, time i h (the composition engine and Odeint's fixed-step loop
///                    under one observer: run_support.hpp);
///   FictitiousSteps  steps of ds in a fictitious time, to exactly an end time or a number of steps
///                    (FictitiousLoop, adaptive/run.cpp: time-transformed and regularised methods);
///   ControlledSteps  step-size control to exactly t_end at tolerance tol per step from a first trial
///                    step h0 (controlled_loop, run_support.hpp: Boost.Odeint's and GSL's steppers).
/// dt_out > 0 (with a sink) hands the sink the states at t = k dt_out and at the end instead of every
/// `every`-th step's; fixed and controlled steps reach an output time inside a step by a shorter step of
/// the same method from that step's start (integrate.cpp), fictitious steps inside their loop.
struct FixedSteps {
  double h;
  long steps;
  double dt_out = 0.0;
};
/// How a run of fictitious steps ends: at exactly this physical time, or after this many steps.
struct EndTime {
  double t;
};
struct StepCount {
  long n;
};
struct FictitiousSteps {
  double ds;
  std::variant<EndTime, StepCount> end;
  double dt_out = 0.0;
  /// Each step of ds taken as this many steps of ds / group, the last one solved to land on the end time too:
  /// the run of ds with every step halved (group 2), a companion that refines each of the run's steps, its
  /// landing step included (a Stepper's segment shorter than a step is one landing step, which a companion at
  /// ds/2 takes as the same single step where the segment is shorter than ds/2). Without dt_out or observers that
  /// look inside a step (events): their states between steps come from a step of the whole group's length.
  int group = 1;
  /// The end time (0 when the run counts steps) and the number of steps (0 when it runs to a time).
  [[nodiscard]] double t_end() const { return end.index() == 0 ? std::get<EndTime>(end).t : 0.0; }
  [[nodiscard]] long steps() const { return end.index() == 1 ? std::get<StepCount>(end).n : 0; }
};
struct ControlledSteps {
  double h0, t_end, tol;
  double dt_out = 0.0;
};
struct MethodInfo;
/// The accuracy mode: the final state's relative error max(|dR|/|R|, |dv|/|v|) at t_end is to be at
/// most tol; the step (h, or ds) is searched with a Richardson error estimate (adaptive/tolerance.hpp).
struct Accuracy {
  double tol, t_end;
  double dt_out = 0.0;  ///< with a sink: samples at t = k dt_out
  /// A step planned for this scene (a map's plan: the step its pilot row delivered, carried to the rows
  /// that choose the same method): the search starts its ladder there, the answer at this step and its
  /// companion at twice it, instead of its own pilot pair; 0: the search's own pilot. Either way the
  /// delivered estimate is the ladder's, trusted by the same rules.
  double first_step = 0.0;
  /// The method first_step was delivered by: where the run's method is another, first_step is not its plan
  /// and the search starts from its own pilot. nullptr: first_step is the run's method's, whichever it is.
  const MethodInfo* first_step_of = nullptr;
};
using Advance = std::variant<FixedSteps, FictitiousSteps, ControlledSteps, Accuracy>;

/// A request backwards in time, from t = 0 to a negative end: FixedSteps with h < 0, FictitiousSteps
/// with a negative end time (or ds < 0 for a count of steps), ControlledSteps and Accuracy with t_end < 0.
bool is_backward(const Advance& how);
/// The same request forwards: every time and step by its magnitude.
Advance forwards(Advance how);
/// The same request backwards (forwards(how) with its times and steps negated as is_backward reads them).
Advance backwards(Advance how);

/// Every number of `how` checked, each with one message naming the quantity: steps and times finite
/// and > 0, counts >= 1, dt_out >= 0, a tolerance per step in [1e-15, inf). The accuracy mode's
/// tolerance is checked by check_tolerance (accuracy.hpp).
void check(const Advance& how);

/// What a run asks for besides the way of advancing time; the API's Options add events and the bound
/// on the energy error. By default the invariants are tracked and nothing else is kept.
struct RunOptions {
  bool track_invariants = true;
  /// Receives the observed states (the first, every `every`-th and the last; with dt_out > 0 the states
  /// at t = k dt_out and the last). nullptr: no samples.
  const SampleSink* sink = nullptr;
  long every = 1;
  /// Time-transformed methods: the constant c of the time-step function (logH: Pi + c, TTL:
  /// sum |A_i|/r_i + c), so the physical step is at most ds/c; < 0: chosen from the scene.
  double omega_c = -1.0;
  /// Also hands the sink the states a method knows inside its steps, flagged Sample::inside, before the
  /// step's end: far-ip's collocation points (its step's dense output, as accurate as the step's end), where
  /// one step holds several turns of the spin and an event's sign can change and change back. Event
  /// location watches them; the other methods' steps hold no such states.
  bool inside_steps = false;
  /// A time-transformed method's auxiliary variable at the start (RunResult::carried of the run that ended
  /// in this state); NaN: its value on the energy shell of the start. A Stepper carries it from segment to
  /// segment: set afresh, logH's g = E - T moved each segment onto the energy of its start, which near a
  /// close pass is off by the energy error's excursion there (table 3.1 at B = 0.9, d = 4, L = 40, logh-pefrl
  /// ds = 0.003: 7 segments 3.7e-8 from one run's 2.3e-10).
  double carried = std::numeric_limits<double>::quiet_NaN();
  /// When given, polled every kPollStride steps of every loop (searches, companions and event
  /// refinements included): once another thread or a signal handler sets it, the run ends as
  /// Outcome::failed with the reason kStoppedOnRequest. The Python module's Ctrl-C and max_seconds.
  const std::atomic<bool>* cancel = nullptr;
};
/// The reason of a run that RunOptions::cancel ended.
inline constexpr const char* kStoppedOnRequest = "stopped on request (an interrupt or the time budget)";
/// Throws Error unless every >= 1 (check_every) and omega_c is finite (< 0: automatic).
void check(const RunOptions& options);

/// Why a method cannot run a (valid) scene, in one line; empty when it can. A family's assumptions:
/// Coulomb's law and the sign of A for the time transformations, B = 0 and one centre for ks.
struct MethodInfo;
using SceneCheck = std::string (*)(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres);

/// How a method advances time: the Advance alternative its driver takes.
enum class Stepping {
  fixed,       ///< FixedSteps: a fixed physical step h
  fictitious,  ///< FictitiousSteps: a fixed fictitious step ds, a variable physical one
  controlled,  ///< ControlledSteps: a tolerance per step, its own step-size control
};
/// How the accuracy mode (tolerance.hpp) searches a method's step.
enum class SearchStrategy {
  none,        ///< not searched: it controls its own step (a tolerance per step), or has no fixed order
  ladder,      ///< Richardson over a ladder of runs (a fixed order p)
  exact_pair,  ///< an exact flow in fictitious time (ks): what runs at ds and a finer ds differ by
  field_pair,  ///< far-ip: what runs from moved starts differ by, its step set by the field's slow scale
};

/// What the code asks of a method besides its name, order and cost: one row of the catalogue
/// (catalogue_traits, run.cpp, sets it from the family), so no code outside it tests a family's name.
struct MethodTraits {
  /// The family's name as `bodypoint methods --markdown` prints it ("exact Lie-Poisson").
  std::string_view family_name;
  /// The family as one word, for machine-read tables (`bodypoint methods --csv`, Python's `methods()`,
  /// the paper's scripts): "lie-poisson".
  std::string_view family_key;
  Stepping stepping = Stepping::fixed;
  SearchStrategy search = SearchStrategy::ladder;
  /// A general-purpose peer bodypoint's methods compete with (Boost.Odeint, GSL, Mikkola's logh-bs).
  bool peer = false;
  /// Another project's code, driven as its users drive it (Boost.Odeint, GSL): a comparison "against a peer"
  /// names one of these (logh-bs is a peer's algorithm in bodypoint's own code).
  bool third_party = false;
  /// Its stages follow the motion about a centre exactly (the orbital resolution check is skipped).
  bool orbit_exact = false;
  /// In free flight its drift turns the spin exactly (the spin resolution check is skipped there).
  bool free_flight_spin_exact = false;
  /// A step resolves its own inside (an extrapolated macro step, a collocation step): what one step turns
  /// the spin or the direction to a centre by says nothing.
  bool macro_steps = false;
  /// Exact in its fictitious time (ks): a run and its companion differ by rounding and the time equation.
  bool exact_in_fictitious_time = false;
  /// Its fictitious time is transformed with the time-step constant c (Options::omega_c).
  bool takes_omega_c = false;
  /// Freezes the gyroscopic term (the thesis's schemes): first order for B != 0, whatever its table.
  bool frozen_gyroscopic_term = false;
  /// In the thesis's "fixed" set (`--methods fixed`): a fixed physical step of its own.
  bool in_fixed_set = false;
  /// What sets its cost per step where the step and the field do, not a number of stages, as the method table
  /// prints it (far-ip: "points x sweeps"); empty: its stages do.
  std::string_view cost_set_by = {};
  /// What the family's flows preserve (geometry_text adds a splitting's symmetry).
  std::string_view geometry;
  /// Where the accuracy mode's search starts on a body for a run to t_end: its first, coarse step (h or ds).
  double (*first_step)(const Body& b, const std::vector<Centre>& centres, double t_end) = nullptr;
};

struct MethodInfo {
  std::string name;
  Family family;
  int order;            ///< nominal order (thesis family: of the underlying table; 0: variable)
  int stages;           ///< sub-steps (kicks) per step as written
  int evals_per_step;   ///< force evaluations per step in a long run without per-step output
  std::string description;
  /// The driver: takes the Advance alternative of its kind (never Accuracy), already checked.
  RunResult (*run)(const Body&, const std::vector<Centre>&, const Advance&, const RunOptions&);
  SceneCheck check = nullptr;  ///< nullptr: runs every valid scene
  /// The number of its kernel that runs vector lanes of trajectories in lockstep (batch.hpp;
  /// splitting/catalogue.hpp numbers them); -1: none.
  int batch_kernel = -1;
  /// What differs between methods beyond the above (set by the catalogue from the family).
  MethodTraits traits = {};
  /// The composition table a splitting method applies (its tag: "y4", "kl6", ...; the part of its name
  /// after the family's prefix); empty for the others. Asked by `auto` (methods.hpp: method_of).
  std::string table = {};
  /// A splitting whose step is its own adjoint (its sub-flows read the same backwards: composition.hpp);
  /// false for every other method.
  bool symmetric = false;
};

/// What a method preserves, in words (`bodypoint methods --csv`, the paper's table of families): its family's
/// geometric property and, for a splitting, whether its step is symmetric.
std::string geometry_text(const MethodInfo& m);

/// Why `m` refuses the scene (empty: it accepts it). `run` throws this reason; sweeps, studies,
/// benchmarks and tests ask it instead of knowing which family assumes what.
std::string refusal(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres);

/// True for methods that choose their own steps from a tolerance per step (ControlledSteps):
/// Boost.Odeint's and GSL's controlled steppers, and logh-bs.
inline bool is_step_controlled(const MethodInfo& m) { return m.traits.stepping == Stepping::controlled; }
/// True for methods with a fixed fictitious step (FictitiousSteps): time-transformed and regularised.
inline bool is_time_transformed(const MethodInfo& m) { return m.traits.stepping == Stepping::fictitious; }

// --- a method's behaviour, asked of its row (callers do not switch on its kind or family) ---------------

/// The first trial step of a controlled method's own step-size control where the caller has none, and its
/// tolerance per step.
inline constexpr double kControlledFirstStep = 1e-3;
inline constexpr double kDefaultStepTolerance = 1e-10;
/// A run of `m` to the time `end` (> 0) at its step: the largest fixed step <= step that lands on end, the
/// fictitious step ds = step to that time, or the tolerance per step tol = step (its control starting at
/// min(h0, end)).
Advance advance_to(const MethodInfo& m, double step, double end, double h0 = kControlledFirstStep);
/// How a fixed step lands on an end time: the fewest steps <= h (fixed_steps_to), or the count nearest end/h
/// (the studies' grids, at least one step).
enum class FixedGrid { landing, nearest };
/// A run of a given size, whatever the row's kind: `step` is h, ds, or a controlled method's first trial step
/// (at most the span; 0: kControlledFirstStep), `tol` a controlled method's tolerance per step; to the time `end` (> 0) or, with end 0,
/// for `steps` steps (a controlled method: to the time steps x step).
struct RunAt {
  double step = 0.0;
  double end = 0.0;
  long steps = 0;
  double tol = kDefaultStepTolerance;
  double dt_out = 0.0;
  FixedGrid grid = FixedGrid::landing;
};
Advance advance_of(const MethodInfo& m, const RunAt& r);
/// Whether its own driver lands on output times (FictitiousSteps::dt_out): the others' samples at dt_out are
/// runs from one output time to the next.
bool lands_on_output_times(const MethodInfo& m);
/// Whether a tolerance given with it is its tolerance per step (its own control), not an accuracy to deliver.
bool takes_tolerance_per_step(const MethodInfo& m);
/// Whether its flow is exact (ks in fictitious time): runs at different steps differ by rounding only, so one
/// configuration stands for its ladder and a pair of its runs measures rounding, not truncation.
bool is_exact_flow(const MethodInfo& m);
/// Whether it keeps its order on a spinning body (the thesis's schemes freeze the gyroscopic term: first order).
bool keeps_order_with_spin(const MethodInfo& m);
/// Whether a step the caller chooses and refines (h, or ds) sets its error, so that a ladder of steps converges:
/// not a controlled method (its tolerance does), nor far-ip (the field sets its steps).
bool refines_by_step(const MethodInfo& m);
/// The name of what its step is: "h", "ds" or "tol"; the same as a message names the quantity ("the step h",
/// "the fictitious step ds", "the tolerance per step tol"); its way of advancing time in one word ("fixed",
/// "fictitious", "controlled").
std::string_view step_name(const MethodInfo& m);
std::string_view step_quantity(const MethodInfo& m);
std::string_view stepping_name(const MethodInfo& m);
/// Whether its fictitious time is transformed with a time-step constant c (Options::omega_c): a run of it is
/// reproduced only with both ds and c. The constant of a run delivered with c, or NaN for a method without one.
bool takes_time_step_constant(const MethodInfo& m);
double time_step_constant_of(const MethodInfo& m, double c);
/// Its order on this body: the thesis's schemes freeze the gyroscopic term, first order for B != 0; 0 for a
/// method without a fixed order.
int effective_order(const MethodInfo& m, const Body& b);
/// Its stages and its force evaluations per step as the method tables print them ("-" and "adaptive" for a
/// controlled method, what sets it for one whose cost the step and the field set: MethodTraits::cost_set_by).
std::string stages_text(const MethodInfo& m);
std::string evals_per_step_text(const MethodInfo& m);
/// Where the accuracy mode's search starts for `m` on this body (its first, coarse step: h, or ds), for a run to
/// t_end (catalogue_traits sets each family's rule; docs/measurements.md, "Tuned constants").
double search_first_step(const MethodInfo& m, const Body& b, const std::vector<Centre>& centres, double t_end);

/// How a run ended.
enum class Outcome {
  ok,          ///< the run reached its end in the regime its numbers mean something in
  diverged,    ///< a non-finite state or invariant, or an energy error above kDivergedEnergy
  collision,   ///< diverged, unresolved or inaccurate after falling onto an attracting centre
  refused,     ///< the method does not apply to this scene (not run; the reason says why)
  failed,      ///< started but stopped: a budget, a time transformation that broke down, an accuracy out of reach
  unresolved,  ///< a step turned the spin by more than pi or the direction to a centre by more than pi/2
  inaccurate,  ///< the energy error exceeded the bound asked for (but not 1)
  incomplete,  ///< an encounter whose run ended before the body left: it has no scattering observables
};
/// The outcome as one word, for outputs (ok, diverged, collision, refused, failed, unresolved, inaccurate,
/// incomplete).
std::string_view outcome_name(Outcome o);
/// Whether a run with this outcome reached a final state: neither refused nor failed (its flags aside).
constexpr bool ran(Outcome o) { return o != Outcome::refused && o != Outcome::failed; }

/// The default bound on the relative energy error of a run called ok: a run whose energy is 1% off
/// has lost its trajectory long before (lp-y4 at h = 50 on table 3.1: 4e-2 in energy, 77% in R).
constexpr double kDefaultMaxEnergyError = 1e-2;

/// Fixed steps that land exactly on t_end: n = ceil(t_end / h_max) steps of t_end / n (a quotient
/// within 1e-12 of a whole number counts as that number). Throws Error beyond 1e13 steps.
FixedSteps fixed_steps_to(double t_end, double h_max);


}  // namespace bodypoint
