// `bodypoint simulate`: one method on one scene; readable summary, --json, or a trajectory CSV.
#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/batch.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/run.hpp"
#include "budget.hpp"
#include "cli.hpp"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

namespace bodypoint::cli {
namespace {

std::string scene_header(const po::variables_map& vm, const SceneOptions& o) {
  if (vm.count("scene")) return "scene=" + o.scene_file;
  return describe(o.params);
}

std::string json_body(const RunResult& r, const std::optional<double>& err_R,
                      const std::optional<double>& err_rel = std::nullopt) {
  std::ostringstream os;
  os << "\"R\": " << json_vec(r.final.R) << ", \"v\": " << json_vec(r.final.v)
     << ", \"w\": " << json_vec(r.final.w);
  if (r.invariants) {
    os << ", \"max_rel_dE\": " << json_number(r.invariants->max_rel_dE)
       << ", \"max_rel_dK2sq\": " << json_number(r.invariants->max_rel_dK2sq);
    if (r.invariants->has_K2Q) os << ", \"max_abs_dK2Q\": " << json_number(r.invariants->max_abs_dK2Q);
  }
  if (err_R) os << ", \"err_R\": " << json_number(*err_R);
  if (err_rel) os << ", \"err_rel\": " << json_number(*err_rel);
  if (r.max_step > 0.0)
    os << ", \"accepted_steps\": " << r.steps << ", \"min_step\": " << json_number(r.min_step)
       << ", \"max_step\": " << json_number(r.max_step);
  os << ", \"force_evals\": " << r.force_evals << ", \"wall_s\": " << json_number(r.wall_s);
  return os.str();
}

}  // namespace

RunPlan plan_run(const po::variables_map& vm, const StepOptions& st, const std::string& method_name,
                 bool method_defaulted, double tol) {
  RunPlan plan;
  const bool tol_given = vm.count("tol") && !vm["tol"].defaulted();
  plan.automatic = method_name == "auto" || (tol_given && method_defaulted);
  if (plan.automatic && !tol_given) throw Error("--method auto needs --tol (the accuracy to deliver)");
  plan.method = plan.automatic ? nullptr : &method_or_throw(method_name);
  plan.search = plan.automatic || (tol_given && !is_adaptive(*plan.method));
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
  } else if (is_adaptive(*plan.method)) {
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
  BodyRun b;
  if (!plan.search) {
    b.method = plan.method;
    b.result = run(*plan.method, body, centres, spec, sink);
    return b;
  }
  // The step search, then the delivered run repeated with invariants or output when they are asked for.
  b.method = plan.method ? plan.method : &choose_method(body, centres, plan.tol, &b.why);
  b.search = adaptive::run_to_tolerance(*b.method, body, centres, plan.tol, spec.t_end);
  if (spec.track_invariants || sink)
    b.result = run(*b.method, body, centres, adaptive::delivered_spec(*b.method, *b.search, spec.t_end, spec), sink);
  else
    b.result = b.search->result;
  return b;
}

namespace {

std::string search_json(const BodyRun& b, double tol) {
  if (!b.search) return "";
  std::ostringstream os;
  os << ", \"tol\": " << json_number(tol) << ", \"err_estimate\": " << json_number(b.search->err_estimate)
     << ", \"h_chosen\": " << json_number(b.search->h) << ", \"search_runs\": " << b.search->runs
     << ", \"search_force_evals\": " << b.search->total_force_evals
     << ", \"search_wall_s\": " << json_number(b.search->total_wall_s);
  if (!b.why.empty()) os << ", \"chosen\": \"" << b.why << "\"";
  return os.str();
}

std::string search_line(const BodyRun& b) {
  std::ostringstream os;
  os << "method=" << b.method->name;
  if (b.search)
    os << (is_time_transformed(*b.method) ? " ds=" : " h=") << fmt(b.search->h)
       << " err_estimate=" << fmt(b.search->err_estimate) << " search: " << b.search->runs << " runs, "
       << b.search->total_force_evals << " force evaluations";
  return os.str();
}

}  // namespace

int cmd_simulate(int argc, char** argv) {
  SceneOptions so;
  StepOptions st;
  std::string method_name = "lp-y4";
  std::string out;
  long every = 1;
  double tol = 1e-10, dt_out = 0.0, omega_c = -1.0;
  bool json = false, no_invariants = false, with_reference = false, dry_run = false, quiet = false;
  double max_seconds = 3600.0, max_rows = 1e7;
  po::options_description desc("bodypoint simulate");
  add_scene_options(desc, so);
  add_step_options(desc, st);
  desc.add_options()
      ("method", po::value(&method_name)->default_value(method_name),
       "integration method (see 'bodypoint methods'), or auto (the default with --tol)")
      ("out", po::value(&out), "write the trajectory to this CSV file (atomically)")
      ("tol", po::value(&tol)->default_value(tol),
       "odeint-*/gsl-*: error tolerance per step; any other method: the final state's relative error "
       "(R and v) to deliver, the step is chosen for it")
      ("dt-out", po::value(&dt_out), "with --out, time-transformed methods: write states at t = k dt-out")
      ("omega-c", po::value(&omega_c), "time-transformed methods: constant c added to the time-step function "
       "(physical step <= ds/c); default: from the scene's spin-orbit rate")
      ("every", po::value(&every)->default_value(every), "with --out: write every k-th step (and the last)")
      ("json", po::bool_switch(&json), "print one JSON object instead of the summary")
      ("no-invariants", po::bool_switch(&no_invariants), "do not track the invariants (fastest; final state only)")
      ("dry-run", po::bool_switch(&dry_run), "check every option and the scene, print what would run, run nothing")
      ("max-seconds", po::value(&max_seconds)->default_value(max_seconds),
       "refuse a run whose calibrated estimate exceeds this many seconds")
      ("max-rows", po::value(&max_rows)->default_value(max_rows), "with --out: refuse to write more rows than this")
      ("quiet", po::bool_switch(&quiet), "no estimate and no progress bar on stderr")
      ("reference", po::bool_switch(&with_reference),
       "also report err_R = |R - R_ref| against Boost.Odeint rkf78 in long double at tolerance 1e-16");
  po::variables_map vm;
  if (!parse(argc, argv, desc, vm,
             "usage: bodypoint simulate [options]\n"
             "Integrates the scene (default: thesis table 3.1, h = 1e-4, n = 500000) with one method.\n"
             "With --tol and no --method (or --method auto) the method and its step are chosen to deliver tol."))
    return 0;

  RunPlan plan = plan_run(vm, st, method_name, vm["method"].defaulted(), tol);
  const MethodInfo* fixed_method = plan.method;
  const bool search = plan.search;
  if (plan.automatic) method_name = "auto";
  if (search && vm.count("omega-c")) throw Error("--tol uses the automatic time-step constant: drop --omega-c");
  const Scene scene = make_scene(vm, so);
  RunSpec& spec = plan.spec;
  if (vm.count("dt-out")) {
    if (fixed_method && !is_time_transformed(*fixed_method))
      throw Error("--dt-out is for time-transformed methods (logh-*, ttl-*, ks)");
    if (!(dt_out > 0.0) || !std::isfinite(dt_out)) throw Error("--dt-out must be a finite number > 0");
    if (!vm.count("out")) throw Error("--dt-out needs --out");
    spec.dt_out = dt_out;
  }
  spec.every = every;
  spec.omega_c = omega_c;
  if (every < 1) throw Error("--every must be >= 1");
  spec.track_invariants = !no_invariants;

  if (!(max_seconds > 0.0)) throw Error("--max-seconds must be > 0");
  if (!(max_rows >= 1.0)) throw Error("--max-rows must be >= 1");
  if (vm.count("out") && !search) {
    // Rows the output would get: one per dt-out, or per every-th step (fictitious steps to t_end are
    // not known in advance: the sink counts them and stops the run at the limit).
    const double rows = spec.dt_out > 0.0 ? spec.t_end / spec.dt_out
                        : spec.steps > 0 ? static_cast<double>(spec.steps) / static_cast<double>(spec.every) : 0.0;
    if (rows * static_cast<double>(scene.bodies.size()) > max_rows)
      throw Error("--out would get about " + fmt(std::ceil(rows)) + " rows per body, more than --max-rows " +
                  fmt(max_rows) + " (raise --every or --dt-out, or --max-rows)");
  }
  if (dry_run) {
    std::cout << "would run " << (search ? method_name + " with --tol " + fmt(tol) : std::string(fixed_method->name))
              << " on " << scene.bodies.size() << " body-point(s) and " << scene.centres.size() << " centre(s): ";
    if (search) std::cout << "step search to t_end = " << fmt(spec.t_end);
    else if (is_time_transformed(*fixed_method)) std::cout << "ds = " << fmt(spec.h) << (spec.t_end > 0 ? " to t_end = " + fmt(spec.t_end) : " for " + std::to_string(spec.steps) + " fictitious steps");
    else if (is_adaptive(*fixed_method)) std::cout << "tol = " << fmt(spec.tol) << " to t_end = " << fmt(spec.t_end);
    else std::cout << spec.steps << " steps of h = " << fmt(spec.h);
    std::cout << "\n";
    return 0;
  }
  // Open the output before computing, so an unwritable path fails at once.
  std::unique_ptr<AtomicFile> file;
  SampleSink sink;
  if (vm.count("out")) {
    file = std::make_unique<AtomicFile>(out);
    std::ostream& os = file->stream();
    os << "# bodypoint simulate, revision " << git_revision() << "\n"
       << "# method=" << method_name;
    if (search) os << " tol=" << fmt(tol) << " t_end=" << fmt(spec.t_end);
    else os << " h=" << fmt(spec.h) << " steps=" << spec.steps;
    os << " every=" << spec.every << " " << scene_header(vm, so) << "\n"
       << "# rel_dE = |E-E0|/|E0|, rel_dK2sq = |K2^2-K2^2_0|/K2^2_0, abs_dK2Q = |K2Q-K2Q_0| "
          "(absent with several centres)\n";
    os.precision(17);
  }

  std::vector<BodyRun> runs;
  long rows_written = 0;
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    const Body& body = scene.bodies[b];
    if (file) {
      std::ostream& os = file->stream();
      const bool k2q = scene.centres.size() == 1;
      if (b == 0)
        os << "body,t,Rx,Ry,Rz,vx,vy,vz,wx,wy,wz,rel_dE,rel_dK2sq" << (k2q ? ",abs_dK2Q" : "") << "\n";
      sink = [&os, b, k2q, &rows_written, max_rows](const Sample& s) {
        if (static_cast<double>(++rows_written) > max_rows)
          throw Error("--out reached --max-rows " + fmt(max_rows) + " rows; raise --every or --dt-out, or --max-rows; "
                      "no output written");
        os << b << ',' << s.t << ',' << s.s.R.x() << ',' << s.s.R.y() << ',' << s.s.R.z() << ','
           << s.s.v.x() << ',' << s.s.v.y() << ',' << s.s.v.z() << ',' << s.s.w.x() << ','
           << s.s.w.y() << ',' << s.s.w.z() << ',' << s.rel_dE << ',' << s.rel_dK2sq;
        if (k2q) os << ',' << s.abs_dK2Q;
        os << '\n';
      };
    }
    std::optional<WorkEstimate> estimate;
    if (!search) {
      estimate = estimate_work(*fixed_method, body, scene.centres, spec);
      if (estimate) check_budget(*estimate, max_seconds, quiet || json);
    }
    BodyRun br;
    {
      const ProgressBar bar(estimate, progress_wanted(quiet));
      br = run_body(plan, body, scene.centres, spec, file ? &sink : nullptr);
    }
    if (search && file) file->stream() << "# body " << b << ": " << search_line(br) << "\n";
    const Health health = assess(br.result);
    if (health.status != "ok")
      throw Error("body '" + body.name + "' (" + std::string(br.method->name) + "): " + health.why +
                  (health.status == "collision" ? "; a time-transformed method (ttl-*) or a smaller --h can follow it"
                                                : "; the step is too large for this scene (reduce --h)") +
                  "; no output written");
    if (with_reference) {
      const State ref = reference_state(body, scene.centres, br.result.t_end);
      br.err_R = (br.result.final.R - ref.R).norm();
      br.err_rel = adaptive::state_distance(br.result.final, ref);
    }
    runs.push_back(std::move(br));
  }
  if (file) file->commit();

  if (json) {
    const BodyRun& r0 = runs.front();
    const double h0 = r0.search ? r0.search->h : spec.h;
    std::cout << "{\"method\": \"" << r0.method->name << "\", \"h\": " << json_number(h0)
              << (is_adaptive(*r0.method) ? ", \"tol\": " + json_number(spec.tol) : std::string())
              << search_json(r0, tol) << ", \"steps\": " << r0.result.steps
              << ", \"t_end\": " << json_number(r0.result.t_end) << ", " << json_body(r0.result, r0.err_R, r0.err_rel);
    if (runs.size() > 1) {
      std::cout << ", \"bodies\": [";
      for (std::size_t b = 0; b < runs.size(); ++b)
        std::cout << (b ? ", " : "") << "{\"name\": \"" << scene.bodies[b].name << "\", \"method\": \""
                  << runs[b].method->name << "\"" << search_json(runs[b], tol) << ", "
                  << json_body(runs[b].result, runs[b].err_R, runs[b].err_rel) << "}";
      std::cout << "]";
    }
    std::cout << "}\n";
    return 0;
  }

  const BodyRun& r0 = runs.front();
  std::cout << "bodypoint simulate  method=" << (search ? method_name : std::string(r0.method->name));
  if (search) std::cout << "  tol=" << fmt(tol);
  else std::cout << (is_time_transformed(*r0.method) ? "  ds=" : "  h=") << fmt(spec.h);
  std::cout << "  steps=" << r0.result.steps << "  t_end=" << fmt(r0.result.t_end) << "\n"
            << "scene: " << scene_header(vm, so) << "  (" << scene.centres.size() << " centre(s), "
            << scene.bodies.size() << " body-point(s))\n";
  for (std::size_t b = 0; b < runs.size(); ++b) {
    const RunResult& r = runs[b].result;
    std::cout << "\n[" << scene.bodies[b].name << "]\n";
    if (!runs[b].why.empty()) std::cout << "  chosen: " << runs[b].why << "\n";
    if (runs[b].search) std::cout << "  " << search_line(runs[b]) << "\n";
    std::cout << std::setprecision(12)
              << "  R(t_end) = " << r.final.R.transpose() << "\n"
              << "  v(t_end) = " << r.final.v.transpose() << "\n"
              << "  w(t_end) = " << r.final.w.transpose() << "\n";
    if (r.invariants) {
      std::cout << std::setprecision(3) << std::scientific
                << "  max |E - E0|/|E0|          = " << r.invariants->max_rel_dE << "\n"
                << "  max |K2^2 - K2^2_0|/K2^2_0 = " << r.invariants->max_rel_dK2sq << "\n";
      if (r.invariants->has_K2Q)
        std::cout << "  max |K2Q - K2Q_0|          = " << r.invariants->max_abs_dK2Q << "\n";
      std::cout << std::defaultfloat;
    }
    if (runs[b].err_R)
      std::cout << std::setprecision(3) << std::scientific << "  |R - R_ref| (odeint rkf78, long double) = "
                << *runs[b].err_R << "\n" << std::defaultfloat;
    std::cout << "  force evaluations = " << r.force_evals << ", wall time = " << std::setprecision(3)
              << r.wall_s << " s\n";
  }
  if (file) std::cout << "\ntrajectory written to " << out << "\n";
  return 0;
}

namespace {

/// The README's method table (between its `methods:begin` and `methods:end` markers; ctest
/// ReadmeMethodTableIsGenerated keeps the two equal).
void print_markdown_table() {
  std::cout << "| method | family | order | stages | evals/step | description |\n|---|---|---|---|---|---|\n";
  for (const MethodInfo& m : methods())
    std::cout << "| `" << m.name << "` | " << family_name(m.family) << " | " << (m.order ? std::to_string(m.order) : "var")
              << " | " << (is_adaptive(m) ? "-" : std::to_string(m.stages)) << " | "
              << (is_adaptive(m) ? "adaptive" : std::to_string(m.evals_per_step)) << " | " << m.description << " |\n";
}

void print_table() {
  std::cout << std::left << std::setw(16) << "method" << std::setw(8) << "order" << std::setw(8)
            << "stages" << std::setw(14) << "evals/step" << "description\n";
  for (const MethodInfo& m : methods())
    std::cout << std::left << std::setw(16) << m.name << std::setw(8)
              << (m.order ? std::to_string(m.order) : "var") << std::setw(8)
              << (is_adaptive(m) ? "-" : std::to_string(m.stages)) << std::setw(14)
              << (is_adaptive(m) ? "adaptive" : std::to_string(m.evals_per_step)) << m.description << "\n";
}

}  // namespace

int cmd_methods(int argc, char** argv) {
  po::options_description desc("bodypoint methods");
  bool markdown = false;
  desc.add_options()("markdown", po::bool_switch(&markdown), "print the table as Markdown (README's Methods section)");
  po::variables_map vm;
  if (!parse(argc, argv, desc, vm, "usage: bodypoint methods [--markdown]\nLists every integration method.")) return 0;
  if (markdown) {
    print_markdown_table();
    return 0;
  }
  print_table();
  const Scene probe = thesis_scene(SceneParams{});
  std::string batched;
  for (const MethodInfo& m : methods())
    if (batch::accepts(m, probe.bodies.front(), probe.centres)) batched += (batched.empty() ? "" : ", ") + std::string(m.name);
  std::cout << "\nsweeps run " << batched << " in batches of " << batch::width() << " vector lanes (" << batch::isa()
            << "; one Coulomb centre at the origin, B != 0; the same bits as alone)\n";
  return 0;
}

}  // namespace bodypoint::cli
