// bodypoint: the command line's side of sweeps and grids (the engine is the library's,
// bodypoint/sweep.hpp): ranges and --grid items from text, CSV rows, header and key, threads, shards,
// the journal, shared by `sweep`, `study` and the sweep under mpirun (mpi_sweep.hpp).
#pragma once

#include "bodypoint/model.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/sweep.hpp"
#include "sweep_tasks.hpp"
#include "bodypoint/detail/run_parts.hpp"

#include <ostream>
#include <string>
#include <vector>

namespace bodypoint::cli {

/// Values from --from/--to/--step (linear, computed as from + k step), --log with --points, or a list.
std::vector<double> linear_range(double from, double to, double step);
std::vector<double> log_range(double from, double to, long points);
/// `points` equally spaced values from `from` to `to`, both included.
std::vector<double> linear_points(double from, double to, long points);

/// Parses one --grid item: NAME=FROM:TO:STEP (linear), NAME=log:FROM:TO:POINTS or NAME=a,b,c.
Axis parse_axis(const std::string& item);

/// Runs task i (grid point i / methods, method i % methods) and returns its CSV row.
std::string run_sweep_task(const SweepSpec& spec, std::size_t i);
/// Runs a unit of plan_units (one task, or a batch) and returns its CSV rows in the unit's order; auto's rows
/// from the map's plan where one is given (plan_map: every rank of an MPI sweep makes the same).
std::vector<std::string> run_sweep_unit(const SweepSpec& spec, const std::vector<std::size_t>& unit,
                                        const MapPlan* plan = nullptr);
/// One CSV row (the columns of sweep_header) of a task's result.
std::string format_row(const SweepSpec& spec, const SweepRow& row);

/// How a sweep runs: threads, which tasks (shard K of N takes the tasks with shard_of == K), and a
/// journal that keeps finished rows durably and supplies those of an interrupted run (rows_file.hpp).
class RowJournal;
struct SweepControl {
  unsigned threads = 1;
  bool progress = false;
  std::size_t shard = 0, shards = 1;
  RowJournal* journal = nullptr;
  /// Run tasks that share method and step in batches of vector lanes (bodypoint/batch.hpp): the
  /// same bits, faster; false runs every task alone (--no-simd, for comparison).
  bool simd = true;
  /// validate_sweep ran on the spec in this process already (run_job, before its journal exists).
  bool validated = false;
};

/// Runs the tasks of this shard that the journal does not hold yet, on control.threads threads, and
/// returns every task's CSV row by task index (empty for tasks of other shards). A row's status is ok,
/// diverged or collision (assess() in run.hpp), or refused (not run; the reason column says why).
/// Throws Error for an invalid scene value before running anything, and after the running rows finish
/// when a signal arrived (no row is started after it; the journal keeps the finished ones).
std::vector<std::string> run_sweep(const SweepSpec& spec, const SweepControl& control);
inline std::vector<std::string> run_sweep(const SweepSpec& spec, unsigned threads, bool progress) {
  return run_sweep(spec, SweepControl{threads, progress});
}

/// The CSV header: commented lines (revision, command, parameters, columns) and the column names.
std::vector<std::string> sweep_header(const SweepSpec& spec, const std::string& command);
/// A key of everything that decides the rows (parameters, values, methods, build): shards and
/// journals of one sweep share it.
std::string sweep_key(const SweepSpec& spec);
/// The header and one row per (grid point, method).
void write_sweep_csv(std::ostream& os, const SweepSpec& spec, const std::vector<std::string>& rows,
                     const std::string& command);


}  // namespace bodypoint::cli
