// The command line's run plan: what --method, --tol and the step options ask for (plan_run), and one
// body's run through the library (run_body), shared by simulate and view.
#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/methods.hpp"
#include "cli.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

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
                 const SampleSink* sink) {
  Options options;
  options.track_invariants = spec.track_invariants;
  options.sink = sink;
  options.every = spec.every;
  options.omega_c = spec.omega_c;
  const Advance how = plan.search ? Advance(Accuracy{plan.tol, spec.t_end, spec.dt_out}) : advance_of(*plan.method, spec);
  BodyResult r = integrate_body(body, centres, plan.method, how, options);
  if (r.outcome == Outcome::refused || r.outcome == Outcome::failed) throw Error(r.reason);
  BodyRun b;
  b.method = r.method;
  b.result = std::move(r.run);
  b.search = r.accuracy;
  b.why = std::move(r.chosen);
  b.outcome = r.outcome;
  b.reason = std::move(r.reason);
  return b;
}

}  // namespace bodypoint::cli
