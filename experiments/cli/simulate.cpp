// `bodypoint simulate`: one method on one scene; readable summary, --json, or a trajectory CSV.
#include "process.hpp"
#include "bodypoint/accuracy.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/observables.hpp"
#include "bodypoint/record.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/run.hpp"
#include "budget.hpp"
#include "cli.hpp"
#include "encounter_parts.hpp"
#include "bodypoint/detail/run_parts.hpp"
#include "bodypoint/detail/model_parts.hpp"
#include "checked.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace bodypoint::cli {
namespace {

std::string scene_header(const po::variables_map& vm, const SceneOptions& o) {
  if (vm.count("scene")) return "scene=" + o.scene_file;
  std::string data;  // the asymptotic data the scene was given by (describe shows what they solved)
  if (vm.count("b")) data += " b=" + fmt(o.b);
  if (vm.count("v-inf"))  // which of K1's two roots: the one with an encounter
    data += " v_inf=" + fmt(o.v_inf) + ", K1 above " + fmt(least_approaching_k1(o.params)) +
            " where the guiding centre approaches";
  if (vm.count("arrival-phase")) data += " arrival_phase=" + fmt(o.arrival_phase);
  return describe(o.params) + (data.empty() ? "" : " (solved for" + data + ")");
}

std::string search_line(const BodyResult& b) {
  std::ostringstream os;
  os << "method=" << b.method->name;
  if (b.accuracy)
    os << " " << step_name(*b.method) << "=" << fmt(b.accuracy->h_chosen)
       << (takes_time_step_constant(*b.method) ? " omega_c=" + fmt(b.accuracy->omega_c) : std::string()) << " search: " << b.accuracy->runs
       << " runs (the delivered one included), " << b.accuracy->force_evals << " force evaluations";
  return os.str();
}

/// The run's error estimate, or that it has none, with how it was obtained (ErrorEstimate).
std::string error_line(const ErrorEstimate& e) {
  if (!e.known()) return "estimated relative error: none (" + e.basis + ")";
  std::ostringstream value;
  value.precision(3);
  value << e.value;
  std::string line = "estimated relative error = " + value.str() + " (" + e.basis;
  if (e.force_evals > 0) line += ", " + std::to_string(e.force_evals) + " force evaluations";
  return line + ")";
}

/// An event's error as printed: the number, or why there is none.
std::string error_text(double error) { return std::isfinite(error) ? fmt(error) : std::string("not known"); }

void print_encounter(const std::vector<Event>& events, const BodyResult& run, const std::optional<Encounter>& e) {
  for (const EventHit& h : run.events)
    std::cout << "  event " << events[h.event].label() << ": t = " << fmt(h.t) << ", r = " << fmt(h.r)
              << ", R = " << json_vec(h.s.R) << " (errors: " << error_text(h.t_error) << " in t, " << error_text(h.r_error)
              << " in r, " << error_text(h.state_error) << " of the state)\n";
  if (run.run.stopped) std::cout << "  the run stopped at event " << events[run.events.back().event].label() << "\n";
  else if (run.outcome == Outcome::ok)
    for (const Event& stop : events)  // a stop asked for and not hit: the run went on to its end
      if (stop.stop)
        std::cout << "  the stop event " << stop.label() << " was not hit: the run went on to t = " << fmt(run.run.t_end)
                  << (stop.kind == Event::Kind::closest_approach ? " (its distance was least at an end of the run)" : "")
                  << "\n";
  if (!e) return;
  const Scattering& sc = e->scattering;
  std::cout << "  scattering (asymptotes: " << sc.asymptotes << ")\n";
  if (sc.in)
    std::cout << "    deflection = " << fmt(sc.deflection) << " rad (out of the incoming plane: " << fmt(sc.out_of_plane)
              << ", error " << (std::isfinite(e->out_of_plane_error) ? fmt(e->out_of_plane_error) : "not known")
              << "), impact parameter b = " << fmt(sc.b) << " (model error " << fmt(e->b_error) << "), v_inf = " << fmt(sc.v_inf)
              << " (" << fmt(e->v_inf_error) << ")"
              << ", time delay = " << fmt(sc.time_delay) << " (error "
              << (std::isfinite(e->time_delay_error) ? fmt(e->time_delay_error) : "not known") << ", the run's part "
              << (std::isfinite(e->time_delay_run_error) ? fmt(e->time_delay_run_error) : "not known") << ")\n"
              << "    the asymptotes' model error in the deflection: "
              << (std::isfinite(e->asymptote_error) ? fmt(e->asymptote_error) + " (" : "") << e->asymptote_basis
              << (std::isfinite(e->asymptote_error) ? ")" : "") << "\n"
              << "    the start distance's error in the deflection: "
              << (std::isfinite(e->start_distance_error) ? fmt(e->start_distance_error) + " (" : "")
              << e->start_distance_basis << (std::isfinite(e->start_distance_error) ? ")" : "") << "\n"
              << "    the deflection's total error (the run's, the asymptotes' and the start distance's): "
              << (std::isfinite(e->deflection_error) ? fmt(e->deflection_error) : "not known") << "\n";
  if (std::isfinite(e->r_min))
    std::cout << "    closest approach r_min = " << fmt(e->r_min) << " (error " << error_text(e->r_min_error) << ") at t_min = "
              << fmt(e->t_min) << " (error " << error_text(e->t_min_error) << ")\n";
  else std::cout << "    no closest approach within the run (the distance has no minimum between its ends)\n";
  std::cout << "    K1 turned " << fmt(sc.K1_turn) << " rad, the spin K2 " << fmt(sc.spin_turn) << " rad; K1: "
            << json_vec(sc.K1_start) << " -> " << json_vec(sc.K1_end) << "\n";
}

}  // namespace

namespace {

struct SimulateOptions {
  SceneOptions so;
  StepOptions st;
  std::string method_name = "lp-y4";
  std::string out;
  long every = 1;
  double tol = kDefaultStepTolerance, dt_out = 0.0, omega_c = -1.0;
  bool json = false, no_invariants = false, with_reference = false, dry_run = false, quiet = false, scattering = false;
  bool backward = false;       ///< --backward: from t = 0 back to -t_end
  bool reversibility = false;  ///< --reversibility: the run, then back to its start by the same steps
  std::vector<std::string> event_text, stop_text;
  std::vector<Event> events;  ///< parsed from event_text and stop_text
  /// Each body's events: `events`, and with --scattering those of its encounter (encounter_options).
  std::vector<std::vector<Event>> body_events;
  double max_seconds = 3600.0, max_rows = 1e7;
  std::vector<std::string> observe;
};

void add_simulate_options(po::options_description& desc, SimulateOptions& o) {
  add_scene_options(desc, o.so);
  add_step_options(desc, o.st);
  desc.add_options()
      ("method", defaulted(&o.method_name),
       "integration method (see 'bodypoint methods'), or auto (the default with --tol)")
      ("out", po::value(&o.out), "write the trajectory to this CSV file (atomically)")
      ("observe", po::value(&o.observe)->multitoken(),
       "with --out: also write these observables (e.g. spin_angle; the list is in observables.cpp)")
      ("tol", defaulted(&o.tol),
       "odeint-*/gsl-*: error tolerance per step; any other method: the final state's relative error "
       "(R and v) to deliver, the step is chosen for it")
      ("dt-out", po::value(&o.dt_out), "with --out: write the states at t = k dt-out (and at the end), every method")
      ("omega-c", po::value(&o.omega_c), "time-transformed methods: constant c added to the time-step function "
       "(physical step <= ds/c); default: from the scene's spin-orbit rate")
      ("every", defaulted(&o.every), "with --out: write every k-th step (and the last)")
      ("event", po::value(&o.event_text)->multitoken()->composing(),
       "locate events on the method's own steps and report them: closest (a closest approach; closest:K to "
       "centre K), r=RADIUS (r:K=RADIUS), x=X, y=Y, z=Z or plane=nx,ny,nz,offset")
      ("stop-at", po::value(&o.stop_text)->multitoken()->composing(),
       "end the run at the first hit of this event (same forms as --event; e.g. r=300 once the body has left; "
       "closest: the least distance of the run to --t-end): its state is the final one, its time t_end")
      ("scattering", po::bool_switch(&o.scattering),
       "report the encounter: asymptotes, deflection, impact parameter, closest approach, K1 and spin turn "
       "(docs/physics.md, Scattering)")
      ("json", po::bool_switch(&o.json), "print one JSON object instead of the summary")
      ("no-invariants", po::bool_switch(&o.no_invariants), "do not track the invariants (fastest; final state only)")
      ("dry-run", po::bool_switch(&o.dry_run), "check every option and the scene, print what would run, run nothing")
      ("max-seconds", defaulted(&o.max_seconds),
       "refuse a run whose calibrated estimate exceeds this many seconds")
      ("max-rows", defaulted(&o.max_rows), "with --out: refuse to write more rows than this")
      ("quiet", po::bool_switch(&o.quiet), "no estimate and no progress bar on stderr")
      ("backward", po::bool_switch(&o.backward),
       "integrate backwards in time, from t = 0 to -T (the --t-end or --steps given; --t-end=-T says the same): "
       "every method, through time reversal (v, w -> -v, -w; docs/physics.md)")
      ("reversibility", po::bool_switch(&o.reversibility),
       "after the run, integrate back to its start with the same method and steps and report how far from the "
       "start it lands (a symmetric splitting: round-off), beside the run's estimated error")
      ("reference", po::bool_switch(&o.with_reference),
       "also report err_R = |R - R_ref| against Boost.Odeint rkf78 in long double at tolerance 1e-16");
}

/// The output options, checked against the plan and the scene, set in plan.how and plan.options.
void apply_output_options(const po::variables_map& vm, const SimulateOptions& o, const Scene& scene, RunPlan& plan) {
  // Given, it is used: so it must be a constant c >= 0 of a method that takes one.
  if (vm.count("omega-c")) check_time_step_constant(o.omega_c, plan.method, plan.search);
  if (vm.count("dt-out")) {
    require_positive(o.dt_out, "the output interval dt_out");
    if (!vm.count("out")) throw Error("--dt-out needs --out");
    std::visit([&o](auto& a) { a.dt_out = o.dt_out; }, plan.how);
  }
  if (vm.count("observe") && !vm.count("out")) throw Error("--observe needs --out");
  plan.options.every = check_every(o.every);
  plan.options.omega_c = o.omega_c;
  plan.options.track_invariants = !o.no_invariants;
  require_positive(o.max_seconds, "the budget max_seconds");
  if (!(o.max_rows >= 1.0)) throw Error("--max-rows must be >= 1");
  if (vm.count("out") && !plan.search) {
    // Rows the output would get: one per dt-out, or per every-th step (fictitious steps to t_end are
    // not known in advance: the sink counts them and stops the run at the limit).
    const double span = planned_end(plan), dt_out = output_interval(plan.how);
    const double steps = std::visit(
        [](const auto& a) -> double {
          using A = std::decay_t<decltype(a)>;
          if constexpr (std::is_same_v<A, FixedSteps>) return static_cast<double>(a.steps);
          else if constexpr (std::is_same_v<A, FictitiousSteps>) return static_cast<double>(a.steps());
          else return 0.0;
        },
        plan.how);
    const double rows = dt_out > 0.0 ? span / dt_out : steps / static_cast<double>(o.every);
    if (rows * static_cast<double>(scene.bodies.size()) > o.max_rows)
      throw Error("--out would get about " + fmt(std::ceil(rows)) + " rows per body, more than --max-rows " +
                  fmt(o.max_rows) + " (raise --every or --dt-out, or --max-rows)");
  }
}

void print_dry_run(const RunPlan& plan, const std::string& method_name, const Scene& scene) {
  std::cout << "would run " << (plan.search ? method_name + " with --tol " + fmt(plan.tol) : std::string(plan.method->name))
            << " on " << scene.bodies.size() << " body-point(s) and " << scene.centres.size() << " centre(s): ";
  if (const auto* a = std::get_if<Accuracy>(&plan.how)) std::cout << "step search to t_end = " << fmt(a->t_end);
  else if (const auto* f = std::get_if<FictitiousSteps>(&plan.how))
    std::cout << "ds = " << fmt(f->ds) << (f->t_end() > 0 ? " to t_end = " + fmt(f->t_end()) : " for " + std::to_string(f->steps()) + " fictitious steps");
  else if (const auto* c = std::get_if<ControlledSteps>(&plan.how)) std::cout << "tol = " << fmt(c->tol) << " to t_end = " << fmt(c->t_end);
  else if (const auto* x = std::get_if<FixedSteps>(&plan.how)) std::cout << x->steps << " steps of h = " << fmt(x->h);
  std::cout << "\n";
}

/// The header's steps= of a run: fixed steps, fictitious steps asked for (0: to an end time), and 1
/// for a step-size-controlled run (one call of its controller to the end time).
long header_steps(const Advance& how) {
  if (const auto* f = std::get_if<FixedSteps>(&how)) return f->steps;
  if (const auto* f = std::get_if<FictitiousSteps>(&how)) return f->steps();
  return 1;
}

/// The trajectory file of --out: opened before computing (an unwritable path fails at once), its
/// columns from the observables' list, committed only after every body ran.
class TrajectoryFile {
 public:
  TrajectoryFile(const std::string& path, const SimulateOptions& o, const po::variables_map& vm, const RunPlan& plan,
                 const Scene& scene)
      : file_(path), writer_(file_.stream(), select_observables(scene.centres, o.observe), true), max_rows_(o.max_rows) {
    // The column names come first, the description after them as comments: numpy's
    // genfromtxt(names=True, comments="#") takes the first line for the names, pandas' read_csv
    // (comment="#") the first line that is not a comment; both read the file as it is.
    writer_.header();
    std::ostream& os = file_.stream();
    os << "# bodypoint simulate, revision " << git_revision() << "\n# method=" << o.method_name;
    if (plan.search) os << " tol=" << fmt(plan.tol) << " t_end=" << fmt(planned_end(plan));
    else os << " h=" << fmt(planned_step(plan)) << " steps=" << header_steps(plan.how);
    os << " every=" << plan.options.every << " " << scene_header(vm, o.so) << "\n";
    writer_.help();
    // The body column holds each body's index in the scene (a number, for numpy); its name is here.
    os << "# body names:";
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) os << (i ? ", " : " ") << i << " = " << scene.bodies[i].name;
    os << "\n";
  }
  SampleSink sink(long body, const BodyPoint& p) {
    return [this, body, &p](const Sample& s) {
      if (static_cast<double>(++rows_) > max_rows_)
        throw Error("--out reached --max-rows " + fmt(max_rows_) + " rows; raise --every or --dt-out, or --max-rows; "
                    "no output written");
      writer_.row(body, s, p);
    };
  }
  std::ostream& stream() { return file_.stream(); }
  void commit() { file_.commit(); }

 private:
  AtomicFile file_;
  TrajectoryWriter writer_;
  double max_rows_;
  long rows_ = 0;
};

/// The thesis's scene at 2L with the same asymptotic data (none for a scene file's states), and whether the
/// encounter answers at the limit L -> infinity.
struct FarScene {
  std::function<Expected<Scene>()> far;
  bool at_limit = false;
  std::optional<double> tol;  ///< the accuracy mode's
};
FarScene far_scene_of(const po::variables_map& vm, const SceneOptions& so, const RunPlan& plan) {
  FarScene f;
  if (!vm.count("scene")) f.far = [&so] { return thesis_scene_twice_as_far(so.params, so.b, so.v_inf, so.arrival_phase); };
  f.at_limit = !vm.count("scene") && answers_at_limit(so.b, so.v_inf);
  if (plan.search) f.tol = plan.tol;
  return f;
}

/// The start distance's part of an encounter's error: the thesis's scene at 2L with the same asymptotic
/// data, run to its departure by auto (twice_as_far_tol), or its run beside the encounter's (`twice`); not
/// known for a scene file's states.
long add_start_distance_of(Encounter& e, const FarScene& f, const Body& body, const BodyResult& near, const TwiceAsFar* twice) {
  return add_start_distance(e, body, f.far, f.tol, near.error.for_orbit(), "the scene file gives states, not the thesis's start distance L",
                            {}, f.at_limit, &near, twice);
}

/// One body's run and, with --reference, the reference state at its end.
/// --reversibility: the run taken back to its start by the same method and steps.
struct Reversal {
  double return_error = 0.0;  ///< max(|dR|/|R0|, |dv|/|v0|) of the state back at the start
  double back_estimate = 0.0;  ///< the way back's own estimated error (NaN: none)
  long force_evals = 0;        ///< of the way back, its estimate included
};

struct SimulatedBody {
  BodyResult run;
  std::optional<State> reference;
  std::string no_reference;  ///< with --reference and none: why (the reference run did not stay finite)
  std::optional<Reversal> reversal;
  /// With the reference: |R - R_ref| and the relative error as --tol measures it, max(|dR|/|R_ref|, |dv|/|v_ref|).
  [[nodiscard]] double err_R() const { return (run.run.final.R - reference->R).norm(); }
  [[nodiscard]] double err_rel() const { return bodypoint::state_distance(run.run.final, *reference); }
};

/// The run `fwd` of `body` taken back from its final state to its start time by the same method, step and
/// time-step constant (the accuracy mode's delivered ones), time reversed (is_backward).
Reversal run_back(const RunPlan& plan, const BodyResult& fwd, const Body& body, const std::vector<Centre>& centres) {
  Body there = body;
  there.s0 = fwd.run.final;
  Options options = plan.options;
  const MethodInfo& m = *fwd.method;
  const bool constant = takes_time_step_constant(m);
  Advance how;
  if (fwd.accuracy) {
    StepRequest q;
    q.h = fwd.accuracy->h_chosen;
    q.t_end = -fwd.run.t_end;
    how = advance_for(&m, q);
    if (constant) options.omega_c = fwd.accuracy->omega_c;
  } else {
    if (fwd.run.stopped) throw Error("--reversibility takes a run to its end time, not one a --stop-at event ended");
    how = is_backward(plan.how) ? forwards(plan.how) : backwards(plan.how);
    if (constant && options.omega_c < 0.0) options.omega_c = bodypoint::automatic_omega_c(body, centres, planned_step(plan));
  }
  const BodyResult back = integrate_body(there, centres, &m, how, options);
  if (!ran(back.outcome))
    throw Error("body '" + body.name + "': the way back failed: " + back.reason);
  return {bodypoint::state_distance(back.run.final, body.s0), back.error.value, back.total_force_evals()};
}

/// One body: budget, run (with the progress bar), health, and the reference state when asked for.
SimulatedBody simulate_body(const SimulateOptions& o, const RunPlan& plan, const Body& body, const Scene& scene,
                            const std::vector<Event>& events, const SampleSink* sink, TwiceAsFar* twice) {
  std::optional<WorkEstimate> estimate;
  if (!plan.search) {
    estimate = estimate_work(*plan.method, body, scene.centres, plan.how, plan.options);
    if (estimate) check_budget(*estimate, o.max_seconds, o.quiet || o.json);
  }
  SimulatedBody sb;
  {
    const auto* accuracy = std::get_if<Accuracy>(&plan.how);
    const ProgressBar bar = accuracy ? ProgressBar("searching the step for tol " + fmt(accuracy->tol), progress_wanted(o.quiet))
                                     : ProgressBar(estimate, progress_wanted(o.quiet));
    sb.run = run_body(plan, body, scene.centres, plan.how, sink, events, twice);
  }
  const BodyResult& br = sb.run;
  if (br.outcome != Outcome::ok) {
    const std::string smaller = takes_tolerance_per_step(*br.method) ? "the tolerance is too loose for this scene (reduce --tol"
                                                               : "the step is too large for this scene (reduce --h";
    const bool energy = br.run.invariants && br.run.invariants->max_rel_dE > plan.options.max_energy_error;
    throw Error("body '" + body.name + "' (" + std::string(br.method->name) + "): " + br.reason + "; " +
                (br.outcome == Outcome::collision ? "a time-transformed method (ttl-*) or a smaller --h can follow it"
                 : br.outcome == Outcome::inaccurate
                     ? smaller + ", or raise " + (energy ? "--max-energy-error" : "--max-error") + " if that error will do)"
                     : smaller + ")") +
                "; no output written");
  }
  for (const std::string& w : br.warnings)
    std::cerr << "bodypoint: warning: body '" << body.name << "' (" << br.method->name << "): " << w << "\n";
  if (o.with_reference) {
    // A close fall onto an attracting centre can take the reference's controlled steps to a non-finite
    // state (A = 2, B = 0, d = 1): then there is no reference, said so, not an error of nan.
    const State ref = reference_state(body, scene.centres, br.run.t_end);
    if (ref.R.allFinite() && ref.v.allFinite()) sb.reference = ref;
    else sb.no_reference = "the reference run (odeint rkf78 in long double) did not stay finite on this scene";
  }
  if (o.reversibility) sb.reversal = run_back(plan, br, body, scene.centres);
  return sb;
}

/// A body's JSON fields: the library's record of the run (record.hpp), the reference's (err_R, err_rel,
/// R_ref, v_ref) before the step range and cost, and the encounter's.
Record simulated_record(const SimulatedBody& b, const Advance& how, const std::vector<Event>& events,
                        const std::optional<Encounter>& e) {
  Record r = body_record(b.run, how, events);
  if (b.reference) {
    Record ref;
    ref.number("err_R", b.err_R()).number("err_rel", b.err_rel());
    ref.vector("R_ref", b.reference->R).vector("v_ref", b.reference->v);
    r.insert_before(r.find("accepted_steps") ? "accepted_steps" : "force_evals", ref);
  } else if (!b.no_reference.empty()) {
    Record ref;
    ref.null("err_R").null("err_rel").note("no_reference", b.no_reference);
    r.insert_before(r.find("accepted_steps") ? "accepted_steps" : "force_evals", ref);
  }
  if (e) r.record("scattering", encounter_record(*e));
  if (b.reversal)
    r.record("reversibility", Record()
                                  .number("return_error", b.reversal->return_error)
                                  .number("back_err_estimate", b.reversal->back_estimate)
                                  .count("back_force_evals", b.reversal->force_evals));
  return r;
}

/// The first body's fields at the top level and, with several bodies, the run's totals and every body.
void report_json(const std::vector<SimulatedBody>& runs, const Scene& scene, const RunPlan& plan, const SimulateOptions& o,
                 const std::vector<std::optional<Encounter>>& enc) {
  Record top = simulated_record(runs.front(), plan.how, o.body_events.front(), enc.front());
  if (runs.size() > 1) {
    // The run's totals (the top-level fields above are the first body's): every body's force
    // evaluations, its accuracy search and its events included, and its step-loop time.
    long evals = 0;
    double wall = 0.0;
    std::vector<Record> bodies;
    for (std::size_t b = 0; b < runs.size(); ++b) {
      const BodyResult& r = runs[b].run;
      evals += r.total_force_evals();
      wall += (r.accuracy ? r.accuracy->wall_s : r.run.wall_s) + r.error.wall_s;
      bodies.push_back(Record().text("name", scene.bodies[b].name).append(simulated_record(runs[b], plan.how, o.body_events[b], enc[b])));
    }
    top.record("run", Record().count("bodies", static_cast<long>(runs.size())).count("force_evals", evals).number("wall_s", wall));
    top.records("bodies", std::move(bodies));
  }
  write_json(std::cout, top);
  std::cout << "\n";
}

void report_body(const SimulatedBody& body, const std::string& name) {
  const BodyResult& run = body.run;
  const RunResult& r = run.run;
  std::cout << "\n[" << name << "]\n";
  if (!run.chosen.empty()) std::cout << "  chosen: " << run.chosen << "\n";
  if (run.accuracy) std::cout << "  " << search_line(run) << "\n";
  std::cout << std::setprecision(12) << "  R(t_end) = " << r.final.R.transpose() << "\n"
            << "  v(t_end) = " << r.final.v.transpose() << "\n"
            << "  w(t_end) = " << r.final.w.transpose() << "\n";
  if (r.invariants) {
    std::cout << std::setprecision(3) << std::scientific
              << "  max |E - E0|/|E0|          = " << r.invariants->max_rel_dE << "\n"
              << "  max |K2^2 - K2^2_0|/K2^2_0 = " << r.invariants->max_rel_dK2sq << "\n";
    if (r.invariants->has_K2Q) std::cout << "  max |K2Q - K2Q_0|          = " << r.invariants->max_abs_dK2Q << "\n";
    std::cout << std::defaultfloat;
  }
  std::cout << "  " << error_line(run.error) << "\n";
  if (body.reference)
    std::cout << std::setprecision(3) << std::scientific << "  |R - R_ref| (odeint rkf78, long double) = "
              << body.err_R() << ", relative error (as estimated) = " << body.err_rel() << "\n" << std::defaultfloat;
  else if (!body.no_reference.empty())
    std::cout << "  |R - R_ref|: none (" << body.no_reference << ")\n";
  std::cout << "  force evaluations = " << r.force_evals << ", wall time = " << std::setprecision(3) << r.wall_s
            << " s\n";
  if (body.reversal)
    std::cout << std::setprecision(3) << std::scientific << "  reversibility: back at t = 0 within "
              << body.reversal->return_error
              << " (relative) of the start: the way out's error taken back and the way back's own, composed (a symmetric "
                 "method's cancel in part); the run's estimated error "
              << run.error.value << "; the way back alone, from the final state with the same step"
              << (takes_time_step_constant(*run.method) ? " and omega_c" : "") << ", is off by its own estimate "
              << body.reversal->back_estimate << " (" << body.reversal->force_evals << " force evaluations)\n"
              << std::defaultfloat;
}

void report_text(const std::vector<SimulatedBody>& runs, const Scene& scene, const RunPlan& plan, const SimulateOptions& o,
                 const std::vector<std::optional<Encounter>>& enc, const std::string& header) {
  const std::string& method_name = o.method_name;
  const BodyResult& r0 = runs.front().run;
  std::cout << "bodypoint simulate  method=" << (plan.search ? method_name : std::string(r0.method->name));
  if (plan.search) std::cout << "  tol=" << fmt(plan.tol);
  else std::cout << (is_time_transformed(*r0.method) ? "  ds=" : "  h=") << fmt(planned_step(plan));
  std::cout << "  steps=" << r0.run.steps << "  t_end=" << fmt(r0.run.t_end) << "\n"
            << "scene: " << header << "  (" << scene.centres.size() << " centre(s), " << scene.bodies.size()
            << " body-point(s))\n";
  for (std::size_t b = 0; b < runs.size(); ++b) {
    report_body(runs[b], scene.bodies[b].name);
    print_encounter(o.body_events[b], runs[b].run, enc[b]);
  }
}

/// The events asked for (--event, --stop) and each body's: with --scattering, those of its encounter too
/// (closest approach, and with no end given the departure that ends the run).
void add_events(SimulateOptions& o, const Scene& scene, bool to_departure) {
  for (const std::string& text : o.event_text) o.events.push_back(parse_event(text));
  for (const std::string& text : o.stop_text) {
    o.events.push_back(parse_event(text));
    o.events.back().stop = true;
  }
  for (const Body& body : scene.bodies) {
    Options with{};
    with.events = o.events;
    o.body_events.push_back(o.scattering ? encounter_options(body, scene.centres, with, to_departure).events : o.events);
  }
}

/// Every body's run and, with --scattering, its encounter (the start distance's part with it: an encounter at
/// the limit takes its run from 2L beside it, where far legs serve both).
struct Simulated {
  std::vector<SimulatedBody> runs;
  std::vector<std::optional<Encounter>> enc;
};
Simulated simulate_bodies(const SimulateOptions& o, const RunPlan& plan, const Scene& scene, const FarScene& far, bool to_departure,
                          TrajectoryFile* file) {
  Simulated out;
  std::vector<std::optional<TwiceAsFar>> twice(scene.bodies.size());
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    const Body& body = scene.bodies[b];
    const SampleSink sink = file ? file->sink(static_cast<long>(b), body.p) : SampleSink();
    if (o.scattering && to_departure) twice[b] = twice_as_far_beside(far.far, far.at_limit, body, scene.centres, far.tol);
    out.runs.push_back(simulate_body(o, plan, body, scene, o.body_events[b], file ? &sink : nullptr, twice[b] ? &*twice[b] : nullptr));
    if (file) file->stream() << "# body " << b << ": " << search_line(out.runs.back().run) << "; " << error_line(out.runs.back().run.error) << "\n";
  }
  out.enc.resize(out.runs.size());
  if (!o.scattering) return out;
  for (std::size_t b = 0; b < out.runs.size(); ++b) {
    BodyResult& run = out.runs[b].run;
    out.enc[b] = measure_encounter(scene.bodies[b], scene.centres, run, o.body_events[b]);
    if (out.enc[b]->outcome != Outcome::ok)
      throw Error("body '" + scene.bodies[b].name + "': " + out.enc[b]->reason + "; no output written");
    run.encounter_force_evals = add_start_distance_of(*out.enc[b], far, scene.bodies[b], run, twice[b] ? &*twice[b] : nullptr);
  }
  return out;
}

}  // namespace

int cmd_simulate(int argc, char** argv) {
  SimulateOptions o;
  po::options_description desc("bodypoint simulate");
  add_simulate_options(desc, o);
  po::variables_map vm;
  if (!parse(argc, argv, desc, vm,
             "usage: bodypoint simulate [options]\n"
             "Integrates the scene (default: thesis table 3.1, h = 1e-4, n = 500000) with one method.\n"
             "With --tol and no --method (or --method auto) the method and its step are chosen to deliver tol."))
    return 0;
  const Scene scene = make_scene(vm, o.so);
  // An encounter with no end given runs until every body has left (the departure event), at most
  // kEncounterSpans free passes.
  const bool to_departure = o.scattering && !vm.count("t-end") && vm["steps"].defaulted();
  std::optional<double> span;
  if (to_departure)
    for (const Body& body : scene.bodies) span = std::max(span.value_or(0.0), encounter_span(body, scene.centres));
  RunPlan plan = plan_run(vm, o.st, o.method_name, vm["method"].defaulted(), o.tol, span);
  if (o.backward) {
    if (is_backward(plan.how)) throw Error("--backward with a negative --t-end says it twice: give one");
    if (o.scattering) throw Error("--scattering measures an encounter forwards in time: drop --backward");
    plan.how = backwards(plan.how);
  }
  if (o.scattering && is_backward(plan.how))
    throw Error("--scattering measures an encounter forwards in time: give a positive --t-end");
  if (plan.automatic) o.method_name = "auto";
  apply_output_options(vm, o, scene, plan);
  add_events(o, scene, to_departure);
  if (o.dry_run) {
    print_dry_run(plan, o.method_name, scene);
    return 0;
  }
  std::unique_ptr<TrajectoryFile> file;
  if (vm.count("out")) file = std::make_unique<TrajectoryFile>(o.out, o, vm, plan, scene);
  auto [runs, enc] = simulate_bodies(o, plan, scene, far_scene_of(vm, o.so, plan), to_departure, file.get());
  if (file) file->commit();
  if (o.json) {
    report_json(runs, scene, plan, o, enc);
    return 0;
  }
  report_text(runs, scene, plan, o, enc, scene_header(vm, o.so));
  if (file) std::cout << "\ntrajectory written to " << o.out << "\n";
  return 0;
}

}  // namespace bodypoint::cli
