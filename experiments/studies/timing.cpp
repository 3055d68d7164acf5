// `bodypoint timing`: run time against the number of steps n for each method (thesis fig. 4.12-4.13),
// measured under the commands' timing rules (stopwatch.hpp): warm-up runs, repeats interleaved across
// the methods at each n, wall and CPU time, median and spread per point, one thread, and nothing but
// the run inside the timed region (no invariants, no output).
#include "process.hpp"
#include "timing.hpp"

#include "bodypoint/io.hpp"
#include "budget.hpp"
#include "cli.hpp"
#include "stopwatch.hpp"
#include "sweep.hpp"
#include "sweep_tasks.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>
#include <unistd.h>

namespace bodypoint::cli {

/// Refuses a study whose calibrated time (every n, method, warm-up and repeat) exceeds the budget, and
/// announces one longer than kAnnounceSeconds on stderr (a study of 1e10 steps calibrated at 1,110 s
/// ran without a word).
void check_timing_budget(const TimingSpec& spec, const Scene& scene, double max_seconds) {
  const double bound = max_seconds > 0.0 ? std::min(max_seconds, kAnnounceSeconds) : kAnnounceSeconds;
  double steps = 0.0;
  for (long n : spec.ns) steps += static_cast<double>(n);
  const double runs = static_cast<double>(std::max(spec.warmup, 1L)) + static_cast<double>(spec.repeats);
  // A timed repeat lasts at least kMinRepeatSeconds (a batch of runs when one is shorter).
  const double batches = static_cast<double>(spec.repeats) * static_cast<double>(spec.ns.size()) *
                         static_cast<double>(spec.methods.size()) * kMinRepeatSeconds;
  if (steps * runs * static_cast<double>(spec.methods.size()) * kMaxSecondsPerStep + batches <= bound) return;
  double seconds = batches;
  for (const MethodInfo* m : spec.methods)
    seconds += estimated_seconds(*m, scene.bodies.front(), scene.centres, spec.h, steps, runs);
  if (max_seconds > 0.0 && seconds > max_seconds)
    throw Error("the timing study would take about " + fmt(std::round(seconds)) + " s (calibrated), above --max-seconds " +
                fmt(max_seconds) + ": fewer or smaller n, fewer repeats or warm-up runs, or raise --max-seconds");
  if (seconds > kAnnounceSeconds)
    std::cerr << "bodypoint: the timing study will take about " << fmt(std::round(seconds)) << " s (calibrated)\n";
}

std::vector<TimingRow> run_timing(const TimingSpec& spec, bool progress) {
  if (spec.methods.empty()) throw Error("the method list is empty");
  if (spec.ns.empty()) throw Error("no values of n");
  const TimingRules rules{spec.warmup, spec.repeats, kMinRepeatSeconds};
  check_rules(rules);
  for (long n : spec.ns)
    if (n < 1) throw Error("n must be >= 1, got " + std::to_string(n));
  const Scene scene = thesis_scene(spec.base);
  validate(scene);  // once: the calibration and the timed runs take it as checked
  check_timing_budget(spec, scene, spec.max_seconds);
  std::vector<TimingRow> rows;
  std::size_t done = 0;
  const std::size_t total = spec.ns.size() * spec.methods.size();
  for (long n : spec.ns) {  // at each n, the methods' repeats interleaved
    std::vector<std::function<void()>> runs;
    std::vector<long> evals;
    for (const MethodInfo* m : spec.methods) {
      const Advance how = to_common_end(*m, FixedSteps{spec.h, n}, spec.tol);  // every method to t = h n
      evals.push_back(run_or_throw(*m, scene.bodies.front(), scene.centres, how, unobserved()).force_evals);
      runs.push_back([m, &scene, how] { run_or_throw(*m, scene.bodies.front(), scene.centres, how, unobserved()); });
    }
    const std::vector<Timing> t = time_interleaved(runs, rules);
    for (std::size_t i = 0; i < spec.methods.size(); ++i) rows.push_back({n, spec.methods[i], t[i], evals[i]});
    done += spec.methods.size();
    if (progress) std::cerr << "\r" << done << "/" << total << std::flush;
  }
  if (progress) std::cerr << "\n";
  return rows;
}

void write_timing_csv(std::ostream& os, const TimingSpec& spec, const std::vector<TimingRow>& rows,
                      const std::string& command) {
  const SceneParams& p = spec.base;
  os << "n,method,median_s,min_s,max_s,cpu_s,spread,repeats,flag,force_evals\n"
     << "# bodypoint timing, revision " << git_revision() << "\n"
     << "# command: " << command << "\n"
     << "# scene: " << describe(p) << " h=" << fmt(spec.h) << "\n"
     << "# a call is one run (no invariants, no output), one thread\n"
     << timing_rules_note(TimingRules{spec.warmup, spec.repeats, kMinRepeatSeconds});
  for (const TimingRow& r : rows)
    os << CsvLine().count(r.n).text(r.method->name).num(r.time.wall_s).num(r.time.min_wall_s).num(r.time.max_wall_s)
              .num(r.time.cpu_s).num(r.time.spread()).count(r.time.repeats).quoted(r.time.flag()).count(r.force_evals).str()
       << '\n';
}

/// Largest n of one timing run: 1e10 steps are hours of a 100 ns step, repeated.
constexpr double kMaxTimingSteps = 1e10;

int cmd_timing(int argc, char** argv) {
  SceneOptions so;
  TimingSpec spec;
  std::string methods_arg = "fixed", out, values;
  double from = 500, to = 250000, step = 500;
  po::options_description desc("bodypoint timing");
  add_scene_options(desc, so);
  desc.add_options()
      ("h", defaulted(&spec.h), "step size")
      ("from", defaulted(&from), "smallest n")
      ("to", defaulted(&to), "largest n")
      ("step", defaulted(&step), "increment of n")
      ("values", po::value(&values), "explicit comma-separated values of n instead")
      ("methods", defaulted(&methods_arg), "comma-separated names, 'fixed' (every fixed-step method but the Kepler split kep-*) or 'all'")
      ("repeats", defaulted(&spec.repeats), "timed repeats per point, interleaved across the methods (median, min, max, spread)")
      ("warmup", defaulted(&spec.warmup), "untimed runs before the repeats")
      ("out", po::value(&out), "CSV file (default: standard output)");
  po::variables_map vm;
  if (!parse(argc, argv, desc, vm,
             "usage: bodypoint timing [options]\nRun time of the step loop against the number of steps n."))
    return 0;
  if (vm.count("scene")) throw Error("timing uses the thesis's scene parameters; --scene is not supported");
  spec.base = so.params;
  spec.methods = methods_named(methods_arg);
  std::vector<double> ns;
  if (vm.count("values")) {
    ns = parse_numbers(values, "--values");
  } else {
    ns = linear_range(from, to, step);
  }
  for (double n : ns) spec.ns.push_back(whole_number(n, "n (--values)", kMaxTimingSteps));
  spec.max_seconds = vm["max-seconds"].as<double>();
  std::unique_ptr<AtomicFile> file;
  if (!out.empty()) file = std::make_unique<AtomicFile>(out);
  const auto rows = run_timing(spec, ::isatty(2) == 1);
  const std::string command = command_line(argc, argv);
  if (file) {
    write_timing_csv(file->stream(), spec, rows, command);
    file->commit();
  } else {
    write_timing_csv(std::cout, spec, rows, command);
  }
  return 0;
}

}  // namespace bodypoint::cli
