// bodypoint: how a sweep (sweep.hpp) is run: each point's scene and way of advancing time, the units of
// tasks that share vector lanes, the shards of a split sweep and the runner the commands drive (threads,
// a journal's rows, a stop). Internal to the API and the commands (not installed): an installed program
// calls run_sweep_rows().
#pragma once

#include "bodypoint/sweep.hpp"
#include "bodypoint/detail/run_parts.hpp"

#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace bodypoint {

/// The scene parameters at a grid point.
SceneParams point_params(const SweepSpec& spec, const std::vector<double>& point);
/// The scene at a grid point: the thesis's (point_params), or the scene file's with the axes' keys set
/// and, with the axis kBodyAxis, only that body.
Scene point_scene(const SweepSpec& spec, const std::vector<double>& point);
/// A sweep task's fixed steps: `steps` steps of h, or with t_end > 0 the steps of at most h that land
/// on t_end (fixed_steps_to); under ForceLaw::thesis_code the code's count instead (thesis_code_steps:
/// n - 1 steps of exactly h). Error for an h that is not a finite number > 0 or fewer than one step.
FixedSteps sweep_steps(double h, long steps, double t_end, ForceLaw law = ForceLaw::coulomb);
/// Every method to one end time T = f.h f.steps: fixed-step methods take f, time-transformed ones
/// fictitious steps ds = f.h to T, step-size-controlled ones run to T from a first trial step f.h at
/// tolerance tol per step (the rule of sweeps, the timing study and the step benchmarks).
Advance to_common_end(const MethodInfo& method, const FixedSteps& f, double tol);
/// How `method` advances at a grid point: every method of a sweep ends at the same time T = h n of the
/// point's sweep_steps (h, n): fixed-step methods take those steps, time-transformed ones fictitious
/// steps ds = h to T, step-size-controlled ones run to T from a first trial step h at tolerance tol.
Advance point_advance(const SweepSpec& spec, const MethodInfo& method, const std::vector<double>& point);
/// The same for a sweep's method entry (nullptr: auto, the accuracy mode).
Advance point_advance(const SweepSpec& spec, const MethodInfo* method, const std::vector<double>& point);
/// "d = 5, L = 100": a grid point for messages.
std::string point_label(const SweepSpec& spec, const std::vector<double>& point);

/// The tasks of `todo` in units: batches of up to batch::width() tasks of one method and step whose
/// scenes a batch kernel accepts (with simd), single tasks otherwise.
std::vector<std::vector<std::size_t>> plan_units(const SweepSpec& spec, const std::vector<std::size_t>& todo, bool simd);
/// validate_sweep in parts: the rules of the sweep as a whole (its methods, bounds, axes and their values,
/// the steps of an axis h), then the grid points [from, to) of sweep_points(spec) (each one's scene and
/// every method's way of advancing there, the point named in the message). A command checks the first
/// point before it calibrates its budget on it, the rest after.
void validate_sweep_rules(const SweepSpec& spec);
std::size_t sweep_points(const SweepSpec& spec);
void validate_sweep_points(const SweepSpec& spec, std::size_t from, std::size_t to);

/// A map's plan for its auto rows (SweepSpec::methods' nullptr at SweepSpec::accuracy). Its pilots are a
/// coarser grid inside the map: on an axis of n values, ceil(sqrt(n)) of them, each in the middle of its
/// share of the axis. A pilot's row is searched as a single run is, and the step it delivered, aimed at the
/// search's target share of tol, is the first step (Accuracy::first_step) of the rows nearest to it that
/// choose the same method; a row whose nearest pilot chose another method, or delivered nothing, is searched
/// from its own pilot pair. The plan depends on the sweep alone, never on which rows a shard, a rank or a
/// resumed journal runs, so no row's result does either.
struct MapPlan {
  struct Step {
    const MethodInfo* method = nullptr;  ///< the pilot's choice
    double first_step = 0.0;             ///< 0: the pilot delivered nothing to plan from
  };
  std::map<std::size_t, Step> steps;       ///< by the pilot's task
  std::map<std::size_t, SweepRow> pilots;  ///< the pilots' rows, by task
};
/// The plan of `spec` (empty without auto at an accuracy), its pilots run on `threads` threads.
MapPlan plan_map(const SweepSpec& spec, unsigned threads = 1);

/// Runs one unit; its rows in the unit's order. With a plan, auto's rows start at its steps and a pilot's
/// row is the plan's.
std::vector<SweepRow> run_sweep_unit_rows(const SweepSpec& spec, const std::vector<std::size_t>& unit,
                                          const MapPlan* plan = nullptr);

/// The shard (0 .. shards-1) that runs task i = point * M + method: (point + method) % shards, so that
/// every shard gets every method on an equal share of the points.
std::size_t shard_of(const SweepSpec& spec, std::size_t task, std::size_t shards);

/// How run_sweep_tasks runs.
struct SweepRunner {
  unsigned threads = 1;
  bool simd = true;  ///< batches of vector lanes where a kernel accepts them (false: every task alone)
  /// Receives each finished row, one call at a time, in completion order. An exception from it stops
  /// the handing out of units and is rethrown after the running ones finish.
  std::function<void(SweepRow&&)> on_row;
  /// Asked before each unit: true stops the handing out of units (the running ones finish).
  std::function<bool()> stop;
  /// The caller ran validate_sweep on this spec already (a command checks it before it opens its outputs):
  /// its points are not built and checked a second time.
  bool validated = false;
};

/// Validates the sweep (unless runner.validated), then runs the tasks of `todo` on runner.threads threads.
void run_sweep_tasks(const SweepSpec& spec, const std::vector<std::size_t>& todo, const SweepRunner& runner);

}  // namespace bodypoint
