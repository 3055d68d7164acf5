// The command line's run plan: what --method, --tol and the step options ask for (plan_run), and one
// body's run through the library (run_body), shared by simulate and view.
#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/methods.hpp"
#include "cli.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <type_traits>
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
  plan.tol = tol;
  plan.how = advance_for(plan.method, step_request(vm, st, plan.method, tol));
  plan.search = std::holds_alternative<Accuracy>(plan.how);
  plan.options.max_energy_error = energy_bound(st);
  plan.options.max_error = error_bound(st);
  plan.options.estimate_error = !st.no_error_estimate;
  return plan;
}

double planned_step(const RunPlan& plan) {
  if (const auto* f = std::get_if<FixedSteps>(&plan.how)) return f->h;
  if (const auto* f = std::get_if<FictitiousSteps>(&plan.how)) return f->ds;
  if (const auto* c = std::get_if<ControlledSteps>(&plan.how)) return c->h0;
  return 0.0;
}

double planned_end(const RunPlan& plan) {
  return std::visit(
      [](const auto& a) -> double {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, FixedSteps>) return a.h * static_cast<double>(a.steps);
        else if constexpr (std::is_same_v<A, FictitiousSteps>) return a.t_end();
        else return a.t_end;
      },
      plan.how);
}

BodyRun run_body(const RunPlan& plan, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                 const SampleSink* sink, const std::vector<Event>& events) {
  Options options = plan.options;
  options.events = events;
  options.sink = sink;
  BodyResult r = integrate_body(body, centres, plan.method, how, options);
  if (r.outcome == Outcome::refused || r.outcome == Outcome::failed) throw Error(r.reason);
  BodyRun b;
  b.method = r.method;
  b.result = std::move(r.run);
  b.search = r.accuracy;
  b.error = std::move(r.error);
  b.warnings = std::move(r.warnings);
  b.why = std::move(r.chosen);
  b.outcome = r.outcome;
  b.reason = std::move(r.reason);
  b.events = std::move(r.events);
  b.event_force_evals = r.event_force_evals;
  b.total_force_evals = r.total_force_evals();
  return b;
}

RunResult run_or_throw(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                       const Options& options) {
  Options o = options;
  o.estimate_error = false;
  BodyResult r = integrate_body(body, centres, &m, how, o);
  if (r.outcome == Outcome::refused || r.outcome == Outcome::failed) throw Error(r.reason);
  return std::move(r.run);
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
    if (!std::isfinite(e.normal.norm()))
      throw Error("--event " + text + ": the plane's normal is too long (its length overflows); scale it down");
    return e;
  }
  throw Error("unknown --event '" + text + "': give closest, closest:K, r=RADIUS, r:K=RADIUS, x=X, y=Y, z=Z or "
              "plane=nx,ny,nz,offset");
}

}  // namespace bodypoint::cli
