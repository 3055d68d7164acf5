// bodypoint: sweeps and grids of a scene, part of the public API.
//
// A sweep varies the step h and scene parameters (scene_parameters(): A, m, B, J, d, L, K1, Kx, Kz)
// over given values, one axis or a grid of several (every combination, the last axis fastest), for a
// list of methods. Over a scene file (with_scene_file) it varies the file's keys instead (centre2.A,
// centre1.position.x, body.B, spinning.d: scene_file.hpp), one body per row (the axis "body"). Task i is grid point i / M with method i % M (M methods). Every task is one run of
// the thesis's scene (thesis_scene) at that point, with fixed steps h (or fictitious steps ds = h, or
// a first trial step h for step-size-controlled methods, with tol) to the end time, invariants
// tracked, its error estimated by a companion run (SweepSpec::estimate_error); its result is a typed
// SweepRow. Tasks of one method and step that a batch kernel accepts
// run in the lanes of one vector register, bit for bit as they would alone (batch.hpp).
//
//   bodypoint::SweepSpec s;
//   s.axes = {{"d", {5, 10, 20}}};
//   s.methods = {&bodypoint::method_or_throw("lp-y4")};
//   s.steps = 100000;
//   for (const bodypoint::SweepRow& r : bodypoint::run_sweep_rows(s, 2)) use(r.point, r.result.final);
#pragma once

#include "bodypoint/bodypoint.hpp"

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace bodypoint {

/// The parameters a sweep can vary: the step h, every scene parameter (model.hpp), and the scene's
/// asymptotic data, b (the incoming asymptote's impact parameter: d is solved for it) and v_inf (the
/// speed at infinity: K1 is solved for it) and arrival_phase (the helix's phase at the periapsis: the
/// start phase is solved for it; scattering.hpp, with_asymptotic_data).
inline const std::vector<std::string>& sweep_parameters() {
  static const std::vector<std::string> p = [] {
    std::vector<std::string> names{"h"};
    for (const SceneParameter& q : scene_parameters()) names.emplace_back(q.name);
    names.emplace_back("b");
    names.emplace_back("v_inf");
    names.emplace_back("arrival_phase");
    return names;
  }();
  return p;
}

/// One varied parameter and its values.
struct Axis {
  std::string param;
  std::vector<double> values;
};

/// One sweep: the varied parameters (one, or a grid: every combination, the last axis fastest),
/// methods, and everything else fixed.
struct SweepSpec {
  std::vector<Axis> axes;
  /// The methods of every point; nullptr: auto (the accuracy mode chooses the method for each row).
  std::vector<const MethodInfo*> methods;
  SceneParams base;         ///< the fixed scene parameters (table 3.1 unless changed)
  double h = kDefaultStep;  ///< fixed step (unless an axis varies h)
  long steps = 0;           ///< fixed number of steps, or 0 when t_end is fixed
  double t_end = 0;         ///< fixed end time (steps = ceil(t_end/h), h = t_end/steps), or 0
  double tol = kDefaultStepTolerance;  ///< step-size-controlled methods: tolerance per step
  /// The accuracy mode (Accuracy): every method but the step-size-controlled peers delivers this
  /// relative error of the final state at t_end (needed), its step searched per row; no vector lanes.
  std::optional<double> accuracy = std::nullopt;
  /// Also report each run's encounter (SweepRow::scattering): each task then runs alone through
  /// integrate_body (no vector lanes) with the encounter's events; it stops when the body has left
  /// (the departure event) or at the sweep's end, and is incomplete if it had not left by then.
  bool scattering = false;
  double max_energy_error = kDefaultMaxEnergyError;  ///< Options::max_energy_error of every run
  bool estimate_error = true;                        ///< Options::estimate_error of every run
  double max_error = kDefaultMaxError;               ///< Options::max_error of every run
  /// A scene file's text and name (with_scene_file): each point is this scene with the axes' keys set;
  /// empty: the thesis's scene from `base`.
  std::string scene_text, scene_origin;
  /// RunOptions::cancel of every run, also polled between units (a batch of vector lanes runs to its end,
  /// so rows of more than 1e6 steps then run alone): once set, run_sweep_rows throws Error(kStoppedOnRequest).
  const std::atomic<bool>* cancel = nullptr;
};

/// Number of (grid point, method) tasks; Error above 1e9.
std::size_t task_count(const SweepSpec& spec);
/// The values of the varied parameters at grid point p (in axis order).
std::vector<double> grid_point(const SweepSpec& spec, std::size_t p);
/// The axis of a scene file's sweep that picks its body (values 1..n), one row per body.
inline constexpr const char* kBodyAxis = "body";
/// `spec` over a scene file's text (`origin` names it in messages): checked, and with several bodies
/// the axis kBodyAxis appended (every body of every point its own row). Error for a scene that does not
/// parse or a sweep of the thesis's parameters (d, b, ...) that a scene file does not have.
SweepSpec with_scene_file(SweepSpec spec, std::string text, std::string origin);

/// Throws Error for an empty sweep, or a grid point whose scene or step is invalid (the point named).
void validate_sweep(const SweepSpec& spec);

/// The methods of a list of names for a sweep: methods_named()'s, with "auto" as nullptr.
std::vector<const MethodInfo*> sweep_methods_named(std::string_view list);
/// Whether the sweep has rows of auto.
bool has_auto(const SweepSpec& spec);
/// A sweep of auto alone without an accuracy is the accuracy mode at its tolerance `tol`, to its end time
/// t_end (or h x steps); auto beside named methods needs SweepSpec::accuracy (Error otherwise: the named ones
/// would change their meaning).
void settle_auto(SweepSpec& spec);

/// A fixed asymptotic datum (b, v_inf or arrival_phase) of the sweep: a one-value axis, solved for at every
/// grid point as a varied one is (a sweep over L keeps b, not d; a sweep over b keeps the arrival phase, not
/// the start phase). Throws Error naming it `named_as` (the command's option, Python's keyword) unless it is
/// a finite number (b and v_inf: > 0) that is not an axis of the sweep already.
void fix_asymptotic_datum(SweepSpec& spec, const std::string& datum, double value, const std::string& named_as);

/// One task's result.
struct SweepRow {
  std::size_t task = 0;
  std::vector<double> point;
  const MethodInfo* method = nullptr;  ///< the method that ran (auto's choice for an automatic row)
  bool automatic = false;              ///< the row asked for auto (SweepSpec::methods' nullptr)
  /// ok, diverged, unresolved, inaccurate or collision (assess()), refused (the method does not take
  /// the scene) or failed (the run stopped: a budget, a broken time transformation).
  Outcome outcome = Outcome::ok;
  std::string reason;  ///< one line; empty when ok
  RunResult result;    ///< final state NaN when refused or failed
  ErrorEstimate error;                ///< the run's estimated error, or why it has none (ErrorEstimate)
  std::vector<std::string> warnings;  ///< what a heuristic saw but the estimate overruled
  /// With SweepSpec::scattering, a run that reached its end (outcome ok, or incomplete: an encounter
  /// that had not finished, whose asymptotes and deflection are then NaN): its encounter (time delay
  /// included), the closest approach to any centre (NaN when the distance had no minimum) and the
  /// asymptotes' model error in the deflection (Encounter::asymptote_error).
  std::optional<Scattering> scattering;
  double r_min = Scattering::kNaN, t_min = Scattering::kNaN, asymptote_error = Scattering::kNaN;
  double r_min_error = Scattering::kNaN, t_min_error = Scattering::kNaN;  ///< Encounter's
  /// The start distance's part of the deflection's and the time delay's error, and the deflection's total
  /// error (Encounter's fields of the same names).
  double start_distance_error = Scattering::kNaN, time_delay_error = Scattering::kNaN, deflection_error = Scattering::kNaN;
  long start_distance_force_evals = 0;  ///< the row's encounter from twice its start distance cost these
  long event_force_evals = 0;  ///< locating the row's events and their errors cost these (BodyResult's)
  std::optional<AccuracyReport> accuracy;  ///< with SweepSpec::accuracy: what the search chose and cost
};

/// Every task of the sweep, by task index, on `threads` threads.
/// `progress`, when given, is told (rows done, rows in all) after every row, one call at a time.
std::vector<SweepRow> run_sweep_rows(const SweepSpec& spec, unsigned threads = 1,
                                     const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace bodypoint
