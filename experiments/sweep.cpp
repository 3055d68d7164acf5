// `bodypoint sweep`: one scene or run parameter varied over a range, for a list of methods.
#include "sweep.hpp"

#include "bodypoint/io.hpp"
#include "cli.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>
#include <unistd.h>

namespace bodypoint::cli {
namespace {

/// A copy of `base` with the swept parameter set; h is handled by the caller.
SceneParams with_value(SceneParams p, const std::string& param, double v) {
  if (param == "d") p.start.d = v;
  else if (param == "L") p.start.L = v;
  else if (param == "Kx") p.start.Kx = v;
  else if (param == "Kz") p.start.Kz = v;
  else if (param == "K1") p.start.K1 = v;
  else if (param == "A") p.A = v;
  else if (param == "B") p.B = v;
  else if (param == "J") p.J = v;
  else if (param == "m") p.m = v;
  return p;
}

void progress_bar(std::size_t done, std::size_t total) {
  const int width = 40;
  const int filled = static_cast<int>(width * done / std::max<std::size_t>(total, 1));
  std::cerr << "\r[" << std::string(filled, '#') << std::string(width - filled, ' ') << "] " << done << "/"
            << total << std::flush;
  if (done == total) std::cerr << "\n";
}

}  // namespace

std::vector<double> linear_range(double from, double to, double step) {
  if (!std::isfinite(from) || !std::isfinite(to) || !std::isfinite(step))
    throw Error("--from, --to and --step must be finite numbers");
  if (step == 0.0) throw Error("--step must not be zero");
  if ((to - from) * step < 0.0)
    throw Error("the range never reaches --to: --from " + fmt(from) + " --to " + fmt(to) + " with --step " + fmt(step));
  const double n = std::floor((to - from) / step * (1.0 + 1e-12) + 1e-9);
  if (n > 1e6) throw Error("the range has more than a million values");
  std::vector<double> v;
  for (long k = 0; k <= static_cast<long>(n); ++k) v.push_back(from + static_cast<double>(k) * step);
  return v;
}

std::vector<double> log_range(double from, double to, long points) {
  if (!(from > 0.0) || !(to > 0.0) || !std::isfinite(from) || !std::isfinite(to))
    throw Error("--log needs --from and --to finite and > 0");
  if (points < 2) throw Error("--log needs --points >= 2");
  std::vector<double> v;
  const double a = std::log(from), b = std::log(to);
  for (long k = 0; k < points; ++k) v.push_back(std::exp(a + (b - a) * static_cast<double>(k) / static_cast<double>(points - 1)));
  v.front() = from;
  v.back() = to;
  return v;
}

RunSpec resolve_steps(double h, long steps, double t_end, double tol) {
  if (!std::isfinite(h) || h <= 0.0) throw Error("--h must be a finite number > 0, got " + fmt(h));
  RunSpec spec;
  spec.h = h;
  spec.steps = steps;
  if (t_end > 0.0) {
    const double n = std::ceil(t_end / h * (1.0 - 1e-12));
    if (n > 1e13) throw Error("--t-end / --h asks for more than 1e13 steps");
    spec.steps = static_cast<long>(n);
    spec.h = t_end / static_cast<double>(spec.steps);
  }
  if (spec.steps < 1) throw Error("--steps must be >= 1");
  spec.t_end = spec.h * static_cast<double>(spec.steps);
  spec.tol = tol;
  spec.track_invariants = true;
  return spec;
}

unsigned thread_count(long requested) {
  if (requested < 0) throw Error("--threads must be >= 0");
  if (requested > 0) return static_cast<unsigned>(requested);
  return std::max(1u, std::thread::hardware_concurrency());
}

std::vector<SweepRow> run_sweep(const SweepSpec& spec, unsigned threads, bool progress) {
  if (spec.methods.empty()) throw Error("the method list is empty");
  if (spec.values.empty()) throw Error("the sweep has no values");
  // Build and validate every scene first, so a bad value fails before any work.
  struct Task {
    double value;
    const MethodInfo* method;
    Scene scene;
    RunSpec run;
  };
  std::vector<Task> tasks;
  for (double v : spec.values) {
    Scene scene;
    try {
      scene = thesis_scene(with_value(spec.base, spec.param, v));
    } catch (const Error& e) {
      throw Error(spec.param + " = " + fmt(v) + ": " + e.what());
    }
    const RunSpec rs = resolve_steps(spec.param == "h" ? v : spec.h, spec.steps, spec.t_end, spec.tol);
    for (const MethodInfo* m : spec.methods) tasks.push_back({v, m, scene, rs});
  }
  std::vector<SweepRow> rows(tasks.size());
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex progress_mutex;
  const CooperativeInterrupt stop_at_row_boundary;  // a signal stops the sweep between rows
  auto worker = [&] {
    for (std::size_t i; !interrupted() && (i = next++) < tasks.size();) {
      const Task& t = tasks[i];
      SweepRow& row = rows[i];
      row.value = t.value;
      row.method = t.method;
      try {
        row.result = run(*t.method, t.scene.bodies.front(), t.scene.centres, t.run);
        const Health h = assess(row.result);
        row.status = h.status;
        row.reason = h.why;
      } catch (const std::exception& e) {
        row.status = "refused";
        row.reason = e.what();
        const Vec3 nan = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
        row.result.final = State{nan, nan, nan};
      }
      const std::size_t d = ++done;
      if (progress) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        progress_bar(d, tasks.size());
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < std::min<std::size_t>(threads, tasks.size()); ++k) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  CooperativeInterrupt::check();
  return rows;
}

void write_sweep_csv(std::ostream& os, const SweepSpec& spec, const std::vector<SweepRow>& rows,
                     const std::string& command) {
  const SceneParams& p = spec.base;
  os << "# bodypoint sweep, revision " << git_revision() << "\n"
     << "# command: " << command << "\n"
     << "# varied: " << spec.param << "\n"
     << "# fixed: " << describe(p) << " (the varied one excepted)";
  if (spec.param != "h") os << " h=" << fmt(spec.h);
  if (spec.t_end > 0) os << " t_end=" << fmt(spec.t_end); else os << " steps=" << spec.steps;
  os << "\n"
     << "# columns: " << spec.param << " = value of the varied parameter; method; max_rel_dE = max_i |E_i-E_0|/|E_0|;"
     << " max_rel_dK2sq = max_i |K2^2_i-K2^2_0|/K2^2_0; max_abs_dK2Q = max_i |K2Q_i-K2Q_0|;"
     << " Rx,Ry,Rz = final position; force_evals; wall_s = step-loop time (runs share the cores);"
     << " status = ok | diverged (non-finite, or energy error above 1) | collision (diverged after a fall onto"
     << " an attracting centre) | refused (not run); reason = why, when not ok\n"
     << spec.param << ",method,max_rel_dE,max_rel_dK2sq,max_abs_dK2Q,Rx,Ry,Rz,force_evals,wall_s,status,reason\n";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const SweepRow& r : rows) {
    const InvariantStats s = r.result.invariants ? *r.result.invariants : InvariantStats{nan, nan, nan};
    std::string reason = r.reason;
    std::replace(reason.begin(), reason.end(), '"', '\'');
    os << fmt(r.value) << ',' << r.method->name << ',' << fmt(s.max_rel_dE) << ',' << fmt(s.max_rel_dK2sq) << ','
       << fmt(s.max_abs_dK2Q) << ',' << fmt(r.result.final.R.x()) << ',' << fmt(r.result.final.R.y()) << ','
       << fmt(r.result.final.R.z()) << ',' << r.result.force_evals << ',' << fmt(r.result.wall_s) << ','
       << r.status << ",\"" << reason << "\"\n";
  }
}

std::vector<const MethodInfo*> parse_methods(const std::string& list) {
  std::vector<const MethodInfo*> ms;
  if (list == "all") {
    for (const MethodInfo& m : methods()) ms.push_back(&m);
    return ms;
  }
  if (list == "fixed") {
    for (const MethodInfo& m : methods())
      if (!has_variable_step(m)) ms.push_back(&m);
    return ms;
  }
  for (const std::string& n : split_list(list)) ms.push_back(&method_or_throw(n));
  if (ms.empty()) throw Error("--methods is empty");
  return ms;
}

int cmd_sweep(int argc, char** argv) {
  SceneOptions so;
  StepOptions st;
  std::string param, methods_arg = "fixed", values, out;
  double from = 0, to = 0, step = 0, tol = 1e-10;
  long points = 0, threads = 0;
  bool log = false;
  po::options_description desc("bodypoint sweep");
  add_scene_options(desc, so);
  add_step_options(desc, st);
  desc.add_options()
      ("param", po::value(&param), "parameter to vary: d, L, h, Kx, Kz, K1, A, B, J, m")
      ("from", po::value(&from), "first value")
      ("to", po::value(&to), "last value")
      ("step", po::value(&step), "linear increment")
      ("log", po::bool_switch(&log), "log-spaced values from --from to --to, --points of them")
      ("points", po::value(&points), "with --log: number of values")
      ("values", po::value(&values), "explicit comma-separated values instead of a range")
      ("methods", po::value(&methods_arg)->default_value(methods_arg), "comma-separated names, 'fixed' (every fixed-step method) or 'all'")
      ("tol", po::value(&tol)->default_value(tol), "adaptive methods: error tolerance")
      ("threads", po::value(&threads)->default_value(0), "worker threads (0: all cores)")
      ("out", po::value(&out), "CSV file (default: standard output)");
  po::variables_map vm;
  if (!parse(argc, argv, desc, vm,
             "usage: bodypoint sweep --param P (--from A --to B --step S | --log --from A --to B --points N | --values a,b,c) [options]\n"
             "One CSV row per (value, method): the deviations of the invariants, the final position and the cost."))
    return 0;
  if (param.empty()) throw Error("--param is required (d, L, h, Kx, Kz, K1, A, B, J, m)");
  const auto& ps = sweep_parameters();
  if (std::find(ps.begin(), ps.end(), param) == ps.end())
    throw Error("unknown parameter '" + param + "' (d, L, h, Kx, Kz, K1, A, B, J, m)");
  if (vm.count("scene")) throw Error("sweep varies the thesis's scene parameters; --scene is not supported");
  SweepSpec spec;
  spec.param = param;
  if (vm.count("values")) {
    if (vm.count("from") || vm.count("to") || vm.count("step") || log) throw Error("give --values or a range, not both");
    spec.values = parse_numbers(values, "--values");
  } else {
    if (!vm.count("from") || !vm.count("to")) throw Error("give --from and --to (or --values)");
    if (log) {
      spec.values = log_range(from, to, points);
    } else {
      if (!vm.count("step")) throw Error("give --step (or --log --points N)");
      spec.values = linear_range(from, to, step);
    }
  }
  spec.methods = parse_methods(methods_arg);
  spec.base = so.params;
  spec.h = st.h;
  spec.tol = tol;
  if (vm.count("t-end")) {
    if (!vm["steps"].defaulted()) throw Error("give --steps or --t-end, not both");
    spec.t_end = st.t_end;
    if (!std::isfinite(spec.t_end) || spec.t_end <= 0.0) throw Error("--t-end must be a finite number > 0");
  } else {
    spec.steps = st.steps;
    if (param == "h") throw Error("sweeping h needs a fixed --t-end (the thesis's T = h n)");
  }
  std::unique_ptr<AtomicFile> file;
  if (!out.empty()) file = std::make_unique<AtomicFile>(out);
  const auto rows = run_sweep(spec, thread_count(threads), ::isatty(2) == 1);
  const std::string command = command_line(argc, argv);
  if (file) {
    write_sweep_csv(file->stream(), spec, rows, command);
    file->commit();
  } else {
    write_sweep_csv(std::cout, spec, rows, command);
  }
  return 0;
}

}  // namespace bodypoint::cli
