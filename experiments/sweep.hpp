// bodypoint: parameter sweeps and timing runs, shared by `sweep`, `timing` and `study`.
#pragma once

#include "bodypoint/model.hpp"
#include "bodypoint/run.hpp"

#include <ostream>
#include <string>
#include <vector>

namespace bodypoint::cli {

/// The parameters a sweep can vary.
inline const std::vector<std::string>& sweep_parameters() {
  static const std::vector<std::string> p{"d", "L", "h", "Kx", "Kz", "K1", "A", "B", "J", "m"};
  return p;
}

/// Values from --from/--to/--step (linear, computed as from + k step), --log with --points, or a list.
std::vector<double> linear_range(double from, double to, double step);
std::vector<double> log_range(double from, double to, long points);

/// One sweep: a parameter, its values, methods, and everything else fixed.
struct SweepSpec {
  std::string param;
  std::vector<double> values;
  std::vector<const MethodInfo*> methods;
  SceneParams base;   ///< the fixed scene parameters (table 3.1 unless changed)
  double h = 1e-4;    ///< fixed step (unless param == "h")
  long steps = 0;     ///< fixed number of steps, or 0 when t_end is fixed
  double t_end = 0;   ///< fixed end time (steps = ceil(t_end/h), h = t_end/steps), or 0
  double tol = 1e-10; ///< adaptive methods
};

/// One (value, method) run. status: ok, diverged or collision (assess() in run.hpp), or refused (the
/// method or a budget refused the run; `reason` says why); a row that is not ok says why in `reason`.
struct SweepRow {
  double value = 0.0;
  const MethodInfo* method = nullptr;
  RunResult result;
  std::string status = "refused";
  std::string reason;
};

/// Resolves (h, steps) exactly as `simulate` does: with t_end > 0, steps = ceil(t_end/h) and
/// h = t_end/steps.
RunSpec resolve_steps(double h, long steps, double t_end, double tol);

/// Runs every (value, method) pair on `threads` threads; rows come back in (value, method) order
/// whatever the thread count. Throws Error for an invalid scene value before running anything, and
/// after the running rows finish when a signal arrived (no row is started after it).
std::vector<SweepRow> run_sweep(const SweepSpec& spec, unsigned threads, bool progress);

/// CSV with a commented header (revision, parameters, columns) and one row per (value, method).
void write_sweep_csv(std::ostream& os, const SweepSpec& spec, const std::vector<SweepRow>& rows,
                     const std::string& command);

/// Number of worker threads: --threads, or the hardware concurrency.
unsigned thread_count(long requested);

}  // namespace bodypoint::cli
