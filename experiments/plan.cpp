// The command line's run plan: what --method, --tol and the step options ask for (plan_run), and one
// body's run through the library (run_body), shared by simulate and view.
#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/methods.hpp"
#include "cli.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <utility>
#include <variant>

namespace bodypoint::cli {

RunPlan plan_run(const po::variables_map& vm, const StepOptions& st, const std::string& method_name,
                 bool method_defaulted, double tol) {
  RunPlan plan;
  const bool tol_given = vm.count("tol") && !vm["tol"].defaulted();
  plan.automatic = method_name == "auto" || (tol_given && method_defaulted);
  if (plan.automatic && !tol_given) throw Error("--method auto needs --tol (the accuracy to deliver)");
  plan.method = plan.automatic ? nullptr : &method_or_throw(method_name);
  plan.search = plan.automatic || (tol_given && !is_step_controlled(*plan.method));
  plan.tol = tol;
  plan.max_energy_error = energy_bound(st);
  RunSpec& spec = plan.spec;
  spec.tol = tol;
  if (plan.search) {
    adaptive::check_tolerance(tol);
    if (!vm["h"].defaulted() || !vm["steps"].defaulted())
      throw Error("--tol chooses the step: give --t-end, not --h or --steps");
    spec.t_end = vm.count("t-end") ? st.t_end : st.h * static_cast<double>(st.steps);
    if (!(std::isfinite(spec.t_end) && spec.t_end > 0.0)) throw Error("--t-end must be a finite number > 0");
  } else if (is_time_transformed(*plan.method)) {
    // --h is the fictitious step ds (never adjusted); --t-end runs to exactly that time, otherwise
    // --steps fictitious steps are taken.
    if (!std::isfinite(st.h) || st.h <= 0.0) throw Error("--h must be a finite number > 0");
    if (vm.count("t-end") && !vm["steps"].defaulted()) throw Error("give --steps or --t-end, not both");
    if (vm.count("t-end") && !(std::isfinite(st.t_end) && st.t_end > 0.0))
      throw Error("--t-end must be a finite number > 0");
    if (!vm.count("t-end") && st.steps < 1) throw Error("--steps must be >= 1");
    spec.h = st.h;
    spec.t_end = vm.count("t-end") ? st.t_end : 0.0;
    spec.steps = vm.count("t-end") ? 0 : st.steps;
  } else if (is_step_controlled(*plan.method)) {
    // The method chooses its steps: --h is only the first trial step, --t-end (or h steps) the end.
    if (!std::isfinite(st.h) || st.h <= 0.0) throw Error("--h must be a finite number > 0");
    if (vm.count("t-end") && !vm["steps"].defaulted()) throw Error("give --steps or --t-end, not both");
    if (!vm.count("t-end") && st.steps < 1) throw Error("--steps must be >= 1");
    spec.t_end = vm.count("t-end") ? st.t_end : st.h * static_cast<double>(st.steps);
    if (!(std::isfinite(spec.t_end) && spec.t_end > 0.0)) throw Error("--t-end must be a finite number > 0");
    spec.h = std::min(st.h, spec.t_end);
    spec.steps = 1;
  } else {
    apply_step_options(vm, st, spec);
  }
  return plan;
}

BodyRun run_body(const RunPlan& plan, const Body& body, const std::vector<Centre>& centres, const RunSpec& spec,
                 const SampleSink* sink, const std::vector<Event>& events) {
  Options options;
  options.events = events;
  options.track_invariants = spec.track_invariants;
  options.sink = sink;
  options.every = spec.every;
  options.omega_c = spec.omega_c;
  options.max_energy_error = plan.max_energy_error;
  Advance how = plan.search ? Advance(Accuracy{plan.tol, spec.t_end, spec.dt_out}) : advance_of(*plan.method, spec);
  if (auto* fixed = std::get_if<FixedSteps>(&how)) fixed->dt_out = spec.dt_out;
  if (auto* controlled = std::get_if<ControlledSteps>(&how)) controlled->dt_out = spec.dt_out;
  BodyResult r = integrate_body(body, centres, plan.method, how, options);
  if (r.outcome == Outcome::refused || r.outcome == Outcome::failed) throw Error(r.reason);
  BodyRun b;
  b.method = r.method;
  b.result = std::move(r.run);
  b.search = r.accuracy;
  b.why = std::move(r.chosen);
  b.outcome = r.outcome;
  b.reason = std::move(r.reason);
  b.events = std::move(r.events);
  b.event_force_evals = r.event_force_evals;
  b.total_force_evals = r.total_force_evals();
  return b;
}

namespace {

double event_number(const std::string& text, const std::string& value) {
  std::size_t used = 0;
  double x = 0.0;
  try {
    x = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != value.size() || !std::isfinite(x))
    throw Error("--event " + text + ": '" + value + "' is not a finite number");
  return x;
}

std::size_t event_centre(const std::string& text, const std::string& index) {
  if (index.empty() || index.find_first_not_of("0123456789") != std::string::npos || index.size() > 6)
    throw Error("--event " + text + ": the centre must be an index 0, 1, ...");
  return static_cast<std::size_t>(std::stoul(index));
}

}  // namespace

Event parse_event(const std::string& text) {
  Event e;
  const std::size_t eq = text.find('=');
  const std::string key = text.substr(0, eq), value = eq == std::string::npos ? "" : text.substr(eq + 1);
  const std::string name = key.substr(0, key.find(':'));
  const std::string index = key.find(':') == std::string::npos ? "0" : key.substr(key.find(':') + 1);
  if (name == "closest" && eq == std::string::npos) {
    e.kind = Event::Kind::closest_approach;
    e.centre = event_centre(text, index);
    return e;
  }
  if (name == "r" && eq != std::string::npos) {
    e.kind = Event::Kind::radius;
    e.centre = event_centre(text, index);
    e.value = event_number(text, value);
    if (!(e.value > 0.0)) throw Error("--event " + text + ": the radius must be > 0");
    return e;
  }
  if ((key == "x" || key == "y" || key == "z") && eq != std::string::npos) {
    e.kind = Event::Kind::plane;
    e.normal = key == "x" ? Vec3::UnitX() : key == "y" ? Vec3::UnitY() : Vec3::UnitZ();
    e.value = event_number(text, value);
    return e;
  }
  if (key == "plane" && eq != std::string::npos) {
    double n[4];
    std::size_t from = 0;
    for (int i = 0; i < 4; ++i) {
      const std::size_t comma = i < 3 ? value.find(',', from) : value.size();
      if (comma == std::string::npos) throw Error("--event " + text + ": give plane=nx,ny,nz,offset");
      n[i] = event_number(text, value.substr(from, comma - from));
      from = comma + 1;
    }
    e.kind = Event::Kind::plane;
    e.normal = Vec3(n[0], n[1], n[2]);
    e.value = n[3];
    if (!(e.normal.norm() > 0.0)) throw Error("--event " + text + ": the plane's normal must not be zero");
    return e;
  }
  throw Error("unknown --event '" + text + "': give closest, closest:K, r=RADIUS, r:K=RADIUS, x=X, y=Y, z=Z or "
              "plane=nx,ny,nz,offset");
}

}  // namespace bodypoint::cli
