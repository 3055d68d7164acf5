// The command line's run plan: what --method, --tol and the step options ask for (plan_run), and one
// body's run through the library (run_body), shared by simulate and view.
#include "bodypoint/accuracy.hpp"
#include "bodypoint/methods.hpp"
#include "cli.hpp"
#include "checked.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

namespace bodypoint::cli {

RunPlan plan_run(const po::variables_map& vm, const StepOptions& st, const std::string& method_name,
                 bool method_defaulted, double tol, std::optional<double> end_if_none) {
  RunPlan plan;
  const bool tol_given = vm.count("tol") && !vm["tol"].defaulted();
  plan.automatic = method_name == "auto" || (tol_given && method_defaulted);
  if (plan.automatic && !tol_given) throw Error("--method auto needs --tol (the accuracy to deliver)");
  plan.method = plan.automatic ? nullptr : &method_or_throw(method_name);
  plan.tol = tol;
  plan.how = advance_for(plan.method, step_request(vm, st, plan.method, tol, end_if_none));
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

BodyResult run_body(const RunPlan& plan, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                    const SampleSink* sink, const std::vector<Event>& events, TwiceAsFar* twice) {
  Options options = plan.options;
  options.events = events;
  options.sink = sink;
  detail::check_run(centres, plan.method, how, options);  // the scene was checked where it was made (make_scene)
  BodyResult r = detail::integrate_encounter_checked(body, centres, plan.method, how, options, twice);
  if (!ran(r.outcome)) throw Error(r.reason);
  return r;
}

BodyResult run_unestimated(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                           const Advance& how, const Options& options) {
  Options o = options;
  o.estimate_error = false;
  return integrate_body(body, centres, &m, how, o);
}

RunResult run_or_throw(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                       const Options& options) {
  BodyResult r = run_unestimated(m, body, centres, how, options);
  if (!ran(r.outcome)) throw Error(r.reason);
  return std::move(r.run);
}

}  // namespace bodypoint::cli
