// `bodypoint sweep`: one scene or run parameter varied over a range, for a list of methods.
#include "process.hpp"
#include "sweep.hpp"

#include "bodypoint/io.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/threads.hpp"
#include "bodypoint/record.hpp"
#include "budget.hpp"
#include "cli.hpp"
#include "mpi_sweep.hpp"
#include "rows_file.hpp"
#include "sweep_tasks.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <thread>
#include <tuple>
#include <utility>
#include <unistd.h>

namespace bodypoint::cli {
namespace {

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

std::vector<double> linear_points(double from, double to, long points) {
  if (!std::isfinite(from) || !std::isfinite(to)) throw Error("--from and --to must be finite numbers");
  if (points < 2) throw Error("--points must be >= 2");
  if (points > 1'000'000) throw Error("--points must be at most 1e6");
  std::vector<double> v;
  for (long k = 0; k < points; ++k) v.push_back(from + (to - from) * static_cast<double>(k) / static_cast<double>(points - 1));
  v.back() = to;
  return v;
}

std::vector<double> log_range(double from, double to, long points) {
  if (!(from > 0.0) || !(to > 0.0) || !std::isfinite(from) || !std::isfinite(to))
    throw Error("--log needs --from and --to finite and > 0");
  if (points < 2) throw Error("--log needs --points >= 2");
  // As many as a grid axis may have (whole_number's bound for --grid's N): 1e12 allocated until bad_alloc.
  if (points > 1'000'000) throw Error("--points must be at most 1e6");
  std::vector<double> v;
  const double a = std::log(from), b = std::log(to);
  for (long k = 0; k < points; ++k) v.push_back(std::exp(a + (b - a) * static_cast<double>(k) / static_cast<double>(points - 1)));
  v.front() = from;
  v.back() = to;
  return v;
}

std::string format_row(const SweepSpec& spec, const SweepRow& r) { return csv_row(sweep_record(spec, r)); }

std::vector<std::string> run_sweep_unit(const SweepSpec& spec, const std::vector<std::size_t>& unit, const MapPlan* plan) {
  std::vector<std::string> rows;
  for (const SweepRow& r : run_sweep_unit_rows(spec, unit, plan)) rows.push_back(format_row(spec, r));
  return rows;
}

std::string run_sweep_task(const SweepSpec& spec, std::size_t i) { return run_sweep_unit(spec, {i}).front(); }

std::vector<std::string> run_sweep(const SweepSpec& spec, const SweepControl& control) {
  const std::size_t n = task_count(spec);
  std::vector<std::string> rows(n);
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < n; ++i) {
    if (shard_of(spec, i, control.shards) != control.shard) continue;
    const auto* done = control.journal ? &control.journal->done() : nullptr;
    if (done && done->count(i)) rows[i] = done->at(i);
    else todo.push_back(i);
  }
  std::size_t finished = 0;
  SweepRunner runner;
  runner.threads = control.threads;
  runner.simd = control.simd;
  runner.validated = control.validated;
  runner.stop = [] { return interrupted(); };
  runner.on_row = [&](SweepRow&& r) {  // one call at a time: the rows, the journal, the progress bar
    rows[r.task] = format_row(spec, r);
    if (control.journal) control.journal->append(r.task, rows[r.task]);
    ++finished;
    if (control.progress) progress_bar(finished, todo.size());
  };
  const CooperativeInterrupt stop_at_row_boundary;  // a signal stops the sweep between units
  run_sweep_tasks(spec, todo, runner);
  CooperativeInterrupt::check();
  return rows;
}

/// "1 spinning, 2 material": the bodies of a scene file's sweep by their axis value.
std::string body_names(const SweepSpec& spec) {
  const Scene scene = parse_scene(spec.scene_text, spec.scene_origin);
  std::vector<std::string> names;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) names.push_back(std::to_string(i + 1) + " " + scene.bodies[i].name);
  return join(names, ", ");
}

/// The header's words on an encounter sweep's columns (SweepSpec::scattering).
std::string scattering_columns() {
  return "; r_min,t_min = the closest approach to any centre (located on the method's steps), r_min_error,t_min_error ="
         " their estimated errors (the same event on companion runs at 2h and 4h, the far legs' part added; given by b or"
         " v_inf, r_min_error covers r_min's distance from the limit L -> infinity; NaN: not known);"
         " deflection, out_of_plane = angles between the incoming and outgoing asymptotes (rad);"
         " b_in = impact parameter of the incoming asymptote, v_inf_in = speed at infinity on it (of the guiding centre"
         " for B != 0);"
         " time_delay = against free motion, Coulomb logarithm removed; asymptote_error = the"
         " asymptotes' model error in the deflection (estimated from half the start distance);"
         " start_distance_error = what the start distance L leaves in the deflection against L ->"
         " infinity (the point again from 2L); deflection_error = the deflection's total; time_delay_error = the time"
         " delay's total (the run's part and the start distance's); start_distance_force_evals = what that run from 2L cost;"
         " event_force_evals = what locating the events and their errors cost;"
         " a run that ended before the body left is outcome incomplete, without them;"
         " K1_turn, spin_turn ="
         " angles K1 and K2 turned over the run (rad); K1x,K1y,K1z = final K1;"
         " asymptotes = kepler | guiding-centre | none: why (docs/physics.md, Scattering)";
}

std::vector<std::string> sweep_header(const SweepSpec& spec, const std::string& command) {
  std::string varied;
  bool sweeps_h = false;
  for (std::size_t a = 0; a < spec.axes.size(); ++a) {
    if (a) varied += ", ";
    varied += spec.axes[a].param;
    sweeps_h = sweeps_h || spec.axes[a].param == "h";
  }
  const bool grid = spec.axes.size() > 1;
  std::string fixed = "# fixed: " + (spec.scene_text.empty() ? describe(spec.base) : "scene=" + spec.scene_origin) +
                      (grid ? " (the varied ones excepted)" : " (the varied one excepted)");
  if (!sweeps_h) fixed += " h=" + fmt(spec.h);
  fixed += spec.t_end > 0 ? " t_end=" + fmt(spec.t_end) : " steps=" + std::to_string(spec.steps);
  if (spec.accuracy)
    fixed += " accuracy=" + fmt(*spec.accuracy) + " (the accuracy mode: each row's step searched for it" +
             (has_auto(spec) ? std::string("; auto's rows from the step of their nearest pilot row, named in err_basis)") : std::string(")"));
  if (spec.base.law == ForceLaw::thesis_code) fixed += " (the code's loop: n - 1 steps of exactly h)";
  // The column names come first, the description after them as comments (numpy's
  // genfromtxt(names=True, comments="#") takes the first line for the names; pandas' read_csv(comment="#")
  // the first line that is not a comment).
  std::string columns = csv_header(sweep_record(spec));  // the record's keys (record.hpp)
  return {std::move(columns),
          "# bodypoint sweep, revision " + std::string(git_revision()),
          "# command: " + command,
          "# varied: " + varied + (grid ? " (a grid: every combination, the last one varying fastest)" : "") +
              (std::find_if(spec.axes.begin(), spec.axes.end(), [](const Axis& a) { return a.param == kBodyAxis; }) !=
                       spec.axes.end()
                   ? "; body = which of the scene's bodies (from 1: " + body_names(spec) + ")"
                   : ""),
          fixed,
          "# columns: " + varied + (grid ? " = values of the varied parameters" : " = value of the varied parameter") +
              "; method; max_rel_dE = max_i |E_i-E_0|/|E_0|;"
              " max_rel_dK2sq = max_i |K2^2_i-K2^2_0|/K2^2_0; max_abs_dK2Q = max_i |K2Q_i-K2Q_0|;"
              " Rx,Ry,Rz = final position; force_evals; wall_s = step-loop time (runs share the cores; a batch of"
              " trajectories run in vector lanes shares its time equally);"
              " outcome = ok | diverged (non-finite, or energy error above 1) | unresolved (a step turned the spin by"
              " more than pi or the direction to a centre by more than pi/2) | incomplete (--scattering: the encounter had"
              " not finished) | inaccurate (energy error above"
              " max_energy_error = " + fmt(spec.max_energy_error) + ", or estimated error above max_error = " +
              fmt(spec.max_error) + ") | collision (diverged after a fall onto an"
              " attracting centre) | refused (not run) | failed (started and stopped); reason = why, when not ok;"
              " err_estimate = estimated relative error of the final state, max(|dR|/|R|, |dv|/|v|) (NaN: none),"
              " estimate_force_evals = its companion run's cost, err_basis = how it was estimated or why there is"
              " none; warning = a flag the estimate overruled" +
              (spec.scattering ? scattering_columns() : std::string()) +
              "; steps, t_end = the run's steps and end time; vx,vy,vz, wx,wy,wz = final velocity and angular velocity"};
}

std::string sweep_key(const SweepSpec& spec) {
  std::string s = describe(spec.base) + "|" + fmt(spec.h) + "|" + std::to_string(spec.steps) + "|" + fmt(spec.t_end) + "|" +
                  fmt(spec.tol);
  for (const Axis& a : spec.axes) {
    s.append("|").append(a.param);
    for (double v : a.values) s.append(",").append(fmt(v));
  }
  for (const MethodInfo* m : spec.methods) s.append("|").append(m ? m->name : "auto");
  if (spec.scattering) s.append("|scattering");
  if (spec.accuracy) s.append("|accuracy=").append(fmt(*spec.accuracy));
  s.append("|").append(spec.estimate_error ? fmt(spec.max_error) : "no-estimate").append("|").append(fmt(spec.max_energy_error));
  return sweep_key_of(git_revision(), spec.scene_text, s);
}

void write_sweep_csv(std::ostream& os, const SweepSpec& spec, const std::vector<std::string>& rows,
                     const std::string& command) {
  for (const std::string& line : sweep_header(spec, command)) os << line << "\n";
  for (const std::string& row : rows) os << row << "\n";
}

/// A sweep parameter (sweep_parameters()) or a scene file's key (centre2.A; validate_sweep checks it
/// against the scene); Error naming the valid ones otherwise.
static void check_axis_name(const std::string& name) {
  const auto& ps = sweep_parameters();
  if (std::find(ps.begin(), ps.end(), name) == ps.end() && !is_scene_key(name))
    throw Error(unknown_name("parameter", name, ps) + "; over --scene, a key such as centre2.A or body.B");
}

Axis parse_axis(const std::string& item) {
  const std::size_t eq = item.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error("--grid '" + item + "': give NAME=FROM:TO:STEP, NAME=log:FROM:TO:POINTS or NAME=a,b,c");
  Axis axis{item.substr(0, eq), {}};
  check_axis_name(axis.param);
  std::string spec = item.substr(eq + 1);
  const bool log = spec.rfind("log:", 0) == 0;
  if (log) spec = spec.substr(4);
  std::vector<std::string> parts;
  for (std::size_t from = 0;;) {
    const std::size_t colon = spec.find(':', from);
    parts.push_back(spec.substr(from, colon - from));
    if (colon == std::string::npos) break;
    from = colon + 1;
  }
  const std::string what = "--grid " + axis.param;
  if (parts.size() == 1 && !log) {
    axis.values = parse_numbers(spec, what);
  } else if (parts.size() == 3) {
    const double a = parse_number(parts[0], what), b = parse_number(parts[1], what), c = parse_number(parts[2], what);
    axis.values = log ? log_range(a, b, whole_number(c, what + " points", 1e6)) : linear_range(a, b, c);
  } else {
    throw Error("--grid '" + item + "': give NAME=FROM:TO:STEP, NAME=log:FROM:TO:POINTS or NAME=a,b,c");
  }
  if (axis.values.empty()) throw Error(what + " has no values");
  return axis;
}

namespace {

/// What `sweep` was asked, beyond the SweepSpec: output, resuming, threads and shard.
struct SweepJob {
  SweepSpec spec;
  std::string out;
  bool resume = false;
  long threads = 0;
  std::size_t shard = 0, shards = 1;
  bool sharded = false;  ///< --shard given (1/1 too): the output is a rows file for merge
  bool no_simd = false;
  std::string command;  ///< the command without the options that do not change the rows
  double max_seconds = 0.0;  ///< the budget (--max-seconds; 0: none)
};

/// --shard K/N with 1 <= K <= N.
void parse_shard(const std::string& text, SweepJob& job) {
  const std::size_t slash = text.find('/');
  if (slash == std::string::npos) throw Error("--shard takes K/N (this process's shard K of N, 1 <= K <= N)");
  const double k = parse_number(text.substr(0, slash), "--shard"), n = parse_number(text.substr(slash + 1), "--shard");
  job.shards = static_cast<std::size_t>(whole_number(n, "--shard N", 1e6));
  const long kk = whole_number(k, "--shard K", 1e6);
  if (static_cast<std::size_t>(kk) > job.shards) throw Error("--shard K/N needs K <= N, got " + text);
  job.shard = static_cast<std::size_t>(kk - 1);
  job.sharded = true;
}

/// The command line without --out, --threads, --shard and --resume: the same for every shard, resumed
/// run and thread count of one sweep, so that their CSVs are identical.
std::string science_command(int argc, char** argv) {
  std::string command = "bodypoint";
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--resume" || a == "--no-simd") continue;
    if ((a == "--out" || a == "--threads" || a == "--shard") && i + 1 < argc) {
      ++i;
      continue;
    }
    if (a.rfind("--out=", 0) == 0 || a.rfind("--threads=", 0) == 0 || a.rfind("--shard=", 0) == 0) continue;
    command += " " + a;
  }
  return command;
}

/// The varied parameters from --param and a range or --values, or from --grid items.
std::vector<Axis> parse_axes(const po::variables_map& vm, const std::vector<std::string>& grid) {
  if (!grid.empty()) {
    for (const char* o : {"param", "from", "to", "step", "values", "points"})
      if (vm.count(o)) throw Error("give --grid or --param with a range, not both");
    std::vector<Axis> axes;
    for (const std::string& g : grid) {
      axes.push_back(parse_axis(g));
      for (std::size_t a = 0; a + 1 < axes.size(); ++a)
        if (axes[a].param == axes.back().param) throw Error("--grid names " + axes.back().param + " twice");
    }
    return axes;
  }
  if (!vm.count("param")) throw Error("--param is required (or --grid; parameters: " + join(sweep_parameters(), ", ") + ")");
  const std::string param = vm["param"].as<std::string>();
  check_axis_name(param);
  const bool log = vm["log"].as<bool>();
  if (vm.count("values")) {
    if (vm.count("from") || vm.count("to") || vm.count("step") || log) throw Error("give --values or a range, not both");
    return {{param, parse_numbers(vm["values"].as<std::string>(), "--values")}};
  }
  if (!vm.count("from") || !vm.count("to")) throw Error("give --from and --to (or --values)");
  const double from = vm["from"].as<double>(), to = vm["to"].as<double>();
  if (log) return {{param, log_range(from, to, vm.count("points") ? vm["points"].as<long>() : 0)}};
  if (vm.count("points") && vm.count("step")) throw Error("give --step or --points, not both");
  if (vm.count("points")) return {{param, linear_points(from, to, vm["points"].as<long>())}};
  if (!vm.count("step")) throw Error("give --step or --points (or --log --points N)");
  return {{param, linear_range(from, to, vm["step"].as<double>())}};
}

/// Fixed asymptotic data (--b, --v-inf, --arrival-phase): a one-value axis each, solved for at every grid
/// point (a sweep over L keeps b, not d; a sweep over b keeps the arrival phase, not the start phase:
/// kept as a base parameter instead, the start phase solved at the base's d gave b = 10 an arrival phase
/// other than the one asked for, its deflection 1.7e-7 from simulate's at the same data).
void apply_fixed_data(const po::variables_map& vm, const SceneOptions& so, SweepSpec& spec) {
  for (const auto& [option, datum, value] : {std::tuple{"b", "b", so.b}, std::tuple{"v-inf", "v_inf", so.v_inf},
                                             std::tuple{"arrival-phase", "arrival_phase", so.arrival_phase}})
    if (vm.count(option)) fix_asymptotic_datum(spec, datum, value, std::string("--") + option);
}

/// --h, --steps or --t-end, and the energy bound: every method of the sweep ends at one time.
void apply_steps(const po::variables_map& vm, const StepOptions& st, SweepSpec& spec) {
  spec.h = st.h;
  spec.max_energy_error = energy_bound(st);
  spec.max_error = error_bound(st);
  spec.estimate_error = !st.no_error_estimate;
  bool sweeps_h = false;
  for (const Axis& a : spec.axes) sweeps_h = sweeps_h || a.param == "h";
  if (vm.count("t-end")) {
    if (!vm["steps"].defaulted()) throw Error("give --steps or --t-end, not both");
    spec.t_end = require_positive(st.t_end, "the end time t_end");
  } else {
    spec.steps = st.steps;
    if (sweeps_h) throw Error("sweeping h needs a fixed --t-end (the thesis's T = h n)");
  }
}

/// What the sweep command takes beyond the scene and the steps: the axes, the methods, the accuracy,
/// the output and the sharding; the text options into `methods`, `grid` and `shard`.
void add_sweep_options(po::options_description& desc, SweepJob& job, std::string& methods_arg,
                       std::vector<std::string>& grid, std::string& shard) {
  desc.add_options()
      ("param", po::value<std::string>(), "parameter to vary: d, L, h, Kx, Kz, K1, A, B, J, m, or the asymptotic data b "
       "(impact parameter; d is solved for it), v_inf (speed at infinity; K1 is solved for it) and arrival_phase; "
       "with --scene, a key of the file: centreK.A, centreK.position.x, bodyK.B, NAME.d, body.B (every body), "
       "bodyK.R.x (one row per body of the scene)")
      ("from", po::value<double>(), "first value")
      ("to", po::value<double>(), "last value")
      ("step", po::value<double>(), "linear increment")
      ("log", po::bool_switch(), "log-spaced values from --from to --to, --points of them")
      ("points", po::value<long>(), "number of values from --from to --to (both included; log-spaced with --log)")
      ("values", po::value<std::string>(), "explicit comma-separated values instead of a range")
      ("grid", po::value(&grid)->composing(), "instead of --param: one varied parameter of a grid, NAME=FROM:TO:STEP, "
       "NAME=log:FROM:TO:POINTS or NAME=a,b,c; repeat for each (every combination is run)")
      ("methods", defaulted(&methods_arg), "comma-separated names, 'fixed' (every fixed-step method but the Kepler split kep-*) or "
       "'all'; auto: the accuracy mode chooses each row's method (at --accuracy; listed alone, at --tol; column chosen), "
       "and rows start at the step of their nearest pilot row (docs/physics.md, 'A map at an accuracy')")
      ("tol", defaulted(&job.spec.tol), "adaptive methods: error tolerance")
      ("accuracy", po::value<double>(), "the accuracy mode: every method but the step-size-controlled peers delivers this "
       "relative error of the final state at --t-end, its step searched per row (columns h_chosen, omega_c, search_force_evals)")
      ("threads", po::value(&job.threads)->default_value(0), "worker threads (0: all cores)")
      ("out", po::value(&job.out), "CSV file (default: standard output); with --shard, this shard's rows file")
      ("resume", po::bool_switch(&job.resume), "finish an interrupted run of the same sweep and --out from its journal")
      ("scattering", po::bool_switch(&job.spec.scattering), "also report each run's encounter: closest approach, "
       "deflection, impact parameter b, v_inf, time delay, K1 and spin turn (columns after reason)")
      ("no-simd", po::bool_switch(&job.no_simd), "run every trajectory alone instead of in batches of vector lanes (same numbers, slower; for comparison)")
      ("shard", po::value(&shard), "K/N: run only shard K of N (every method on every N-th grid point, staggered) and write a rows file for 'bodypoint merge'");
}

/// The sweep's methods, base scene, data and steps from the parsed options: a value given is used or refused.
void apply_sweep_options(const po::variables_map& vm, SceneOptions& so, StepOptions& st, const std::string& methods_arg,
                         SweepJob& job) {
  job.spec.methods = sweep_methods_named(methods_arg);
  job.spec.base = so.params;
  // A value given is used, or refused: the tolerance per step whatever the methods, d or K1 beside
  // the asymptotic data solved for them.
  if (!vm["tol"].defaulted()) require_positive(job.spec.tol, "the tolerance per step tol");
  std::vector<std::string> swept, given;
  for (const Axis& a : job.spec.axes) swept.push_back(a.param);
  for (const SceneParameter& q : scene_parameters())
    if (vm.count(std::string(q.name)) && !vm[std::string(q.name)].defaulted()) given.emplace_back(q.name);
  check_data_beside_solved(swept, given);
  apply_fixed_data(vm, so, job.spec);
  apply_steps(vm, st, job.spec);
  if (vm.count("accuracy")) job.spec.accuracy = vm["accuracy"].as<double>();
  settle_auto(job.spec);
  if (vm.count("scene")) {
    for (const SceneParameter& q : scene_parameters())
      if (!vm[std::string(q.name)].defaulted())
        throw Error("--" + std::string(q.name) + " is a thesis parameter: with --scene, set it in the file or sweep its key");
    job.spec = with_scene_file(std::move(job.spec), read_scene_text(so.scene_file), so.scene_file);
  }
}

SweepJob parse_sweep(int argc, char** argv, bool& help) {
  SceneOptions so;
  StepOptions st;
  SweepJob job;
  std::string methods_arg = "fixed", shard;
  std::vector<std::string> grid;
  po::options_description desc("bodypoint sweep");
  add_scene_options(desc, so);
  add_step_options(desc, st);
  add_sweep_options(desc, job, methods_arg, grid, shard);
  po::variables_map vm;
  help = !parse(argc, argv, desc, vm,
                "usage: bodypoint sweep (--param P (--from A --to B --step S | --log --from A --to B --points N | --values a,b,c)"
                " | --grid P=... --grid Q=...) [options]\n"
                "One CSV row per (grid point, method): the deviations of the invariants, the final position and the cost.");
  if (help) return job;
  job.spec.axes = parse_axes(vm, grid);
  if (vm.count("shard")) parse_shard(shard, job);
  if (job.resume && job.out.empty()) throw Error("--resume needs --out (the journal is <out>.journal)");
  if (job.sharded && job.out.empty()) throw Error("--shard needs --out (the shard's rows file)");
  apply_sweep_options(vm, so, st, methods_arg, job);
  job.command = science_command(argc, argv);
  job.max_seconds = vm["max-seconds"].as<double>();
  return job;
}

/// Writes the rows: the CSV, or for a shard its rows file; then the journal is no longer needed.
void write_output(const SweepJob& job, AtomicFile* file, RowJournal* journal, const std::vector<std::string>& rows) {
  if (!file) {
    write_sweep_csv(std::cout, job.spec, rows, job.command);
    return;
  }
  if (job.sharded) {
    RowsContent mine{sweep_key(job.spec), rows.size(), sweep_header(job.spec, job.command), {}};
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (shard_of(job.spec, i, job.shards) == job.shard) mine.rows.emplace(i, rows[i]);
    file->stream() << rows_file_text(mine);
  } else {
    write_sweep_csv(file->stream(), job.spec, rows, job.command);
  }
  file->commit();
  if (journal) journal->remove();
}

/// The journal of a sweep that writes a file (none for standard output, a FIFO or a device).
std::unique_ptr<RowJournal> open_journal(const SweepJob& job, const AtomicFile* file) {
  if (!file) return nullptr;
  if (file->direct()) {
    if (job.resume) throw Error("--resume needs an --out that is a file (a FIFO or device keeps no journal)");
    return nullptr;
  }
  return std::make_unique<RowJournal>(job.out + ".journal", sweep_key(job.spec), task_count(job.spec),
                                      sweep_header(job.spec, job.command), job.resume);
}

/// Under mpirun: rank 0 opens the output and the journal and coordinates; the other ranks compute.
void run_job_mpi(const SweepJob& job) {
  if (job.sharded) throw Error("give --shard or run under mpirun, not both");
  MpiSession mpi;
  const unsigned threads = job.threads == 0 ? 1 : thread_count(job.threads);  // one per rank unless asked; checked
  if (mpi.rank() != 0) {
    if (mpi.agree(false)) run_sweep_mpi(mpi, job.spec, SweepControl{});
    return;
  }
  std::unique_ptr<AtomicFile> file;
  std::unique_ptr<RowJournal> journal;
  try {
    validate_sweep(job.spec);
    if (!job.out.empty()) file = std::make_unique<AtomicFile>(job.out);
    journal = open_journal(job, file.get());
  } catch (...) {
    mpi.agree(false);  // the other ranks stop without running anything
    throw;
  }
  mpi.agree(true);
  const auto rows = run_sweep_mpi(mpi, job.spec, SweepControl{threads, ::isatty(2) == 1, 0, 1, journal.get(), !job.no_simd});
  write_output(job, file.get(), journal.get(), rows);
}

/// The steps of a row on average: those of the step h, or, when h is swept, their mean over its values
/// (h the smallest of them, for the calibration). The steps were checked (validate_sweep_rules, and the
/// first point's by validate_sweep_points).
FixedSteps mean_row_steps(const SweepSpec& spec) {
  for (const Axis& a : spec.axes)
    if (a.param == "h" && !a.values.empty()) {
      double total = 0.0, h = a.values.front();
      for (double value : a.values) {
        total += static_cast<double>(sweep_steps(value, spec.steps, spec.t_end, spec.base.law).steps);
        h = std::min(h, value);
      }
      return {h, static_cast<long>(std::ceil(total / static_cast<double>(a.values.size())))};
    }
  return sweep_steps(spec.h, spec.steps, spec.t_end, spec.base.law);
}

/// Runs the job and writes its CSV (or, for a shard, its rows file), through a journal when it has a file.
/// Refuses a sweep whose calibrated time (every row of this shard, on its threads) exceeds the budget:
/// each method's time per step on the first grid point, times the steps of every row. The sweep's rules
/// and its first point were checked.
void check_sweep_budget(const SweepJob& job) {
  if (!(job.max_seconds > 0.0) || job.spec.accuracy) return;  // a search's cost is not known beforehand
  const std::size_t tasks = task_count(job.spec), methods = job.spec.methods.size();
  const FixedSteps steps = mean_row_steps(job.spec);
  const Scene scene = point_scene(job.spec, grid_point(job.spec, 0));
  const double runs_per_task = job.spec.estimate_error ? 1.0 + ErrorEstimate::kTypicalCost : 1.0;  // and the companion
  if (static_cast<double>(tasks) * static_cast<double>(steps.steps) * runs_per_task * kMaxSecondsPerStep <= job.max_seconds)
    return;
  double seconds = 0.0;
  for (std::size_t k = 0; k < methods; ++k) {
    const MethodInfo& m = *job.spec.methods[k];
    if (!refusal(m, scene.bodies.front(), scene.centres).empty()) continue;
    const double rows = static_cast<double>(tasks / methods) / static_cast<double>(job.shards) * runs_per_task;
    seconds += estimated_seconds(m, scene.bodies.front(), scene.centres, steps.h, static_cast<double>(steps.steps), rows);
  }
  seconds /= static_cast<double>(thread_count(job.threads));
  if (seconds > job.max_seconds)
    throw Error("the sweep would take about " + fmt(std::round(seconds)) + " s (calibrated on its first point), above "
                "--max-seconds " + fmt(job.max_seconds) + ": fewer points or steps, more threads or shards, or raise --max-seconds");
}

void run_job(const SweepJob& job) {
  if (launched_by_mpi()) return run_job_mpi(job);
  // Checked before a journal exists; the budget before every point is, which a sweep of 1e9 points would
  // spend long on, and after the first, on which it calibrates.
  validate_sweep_rules(job.spec);
  validate_sweep_points(job.spec, 0, 1);
  check_sweep_budget(job);
  validate_sweep_points(job.spec, 1, sweep_points(job.spec));
  std::unique_ptr<AtomicFile> file;
  if (!job.out.empty()) file = std::make_unique<AtomicFile>(job.out);
  const std::unique_ptr<RowJournal> journal = open_journal(job, file.get());
  SweepControl control{thread_count(job.threads), ::isatty(2) == 1, job.shard, job.shards, journal.get(), !job.no_simd, true};
  std::vector<std::string> rows;
  try {
    rows = run_sweep(job.spec, control);
  } catch (const Error& e) {
    if (journal && interrupted()) throw Error(std::string(e.what()) + "; the finished rows are in " + journal->path() + ", finish with --resume");
    throw;
  }
  write_output(job, file.get(), journal.get(), rows);
}

}  // namespace

int cmd_sweep(int argc, char** argv) {
  bool help = false;
  const SweepJob job = parse_sweep(argc, argv, help);
  if (!help) run_job(job);
  return 0;
}

}  // namespace bodypoint::cli
