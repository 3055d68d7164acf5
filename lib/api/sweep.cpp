// bodypoint: sweeps and grids (sweep.hpp).
#include "bodypoint/sweep.hpp"

#include "bodypoint/accuracy.hpp"
#include "bodypoint/batch.hpp"
#include "bodypoint/threads.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/scene_file.hpp"
#include "checked.hpp"
#include "choice.hpp"
#include "encounter_parts.hpp"
#include "estimate.hpp"
#include "sweep_tasks.hpp"
#include "bodypoint/detail/run_parts.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <exception>
#include <map>
#include <mutex>
#include <optional>
#include <thread>
#include <tuple>
#include <utility>

namespace bodypoint {
namespace {

double point_h(const SweepSpec& spec, const std::vector<double>& point) {
  for (std::size_t a = 0; a < spec.axes.size(); ++a)
    if (spec.axes[a].param == "h") return point[a];
  return spec.h;
}

/// A row whose run did not happen (refused) or stopped (failed): no state, no invariants.
SweepRow unrun_row(SweepRow row, Outcome outcome, std::string why) {
  const Vec3 nan = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  row.result = RunResult{};
  row.result.final = State{nan, nan, nan};
  row.outcome = outcome;
  row.reason = std::move(why);
  return row;
}

/// Options of every run of the sweep: its bounds and whether its error is estimated.
Options sweep_options(const SweepSpec& spec) {
  Options options;
  options.max_energy_error = spec.max_energy_error;
  options.estimate_error = spec.estimate_error;
  options.max_error = spec.max_error;
  options.cancel = spec.cancel;
  return options;
}

/// The row of a finished run of the public API.
SweepRow result_row(SweepRow row, BodyResult r) {
  if (r.method) row.method = r.method;  // auto's choice
  if (!ran(r.outcome)) return unrun_row(std::move(row), r.outcome, r.reason);
  row.result = std::move(r.run);
  row.outcome = r.outcome;
  row.reason = std::move(r.reason);
  row.error = std::move(r.error);
  row.warnings = std::move(r.warnings);
  row.accuracy = r.accuracy;
  row.event_force_evals = r.event_force_evals;
  return row;
}

/// A batch's companion runs. integrate()'s estimate (estimate_and_settle) runs each lane's companions through
/// run(); a companion one lane asks for runs as one batch with the same companion of every later lane (the
/// rows share the method and the step, and their estimates mostly ask alike; earlier lanes are done). A lane
/// computes the scalar run's bits (batch.hpp) and is judged as integrate() judges a companion, so a batch's
/// rows are integrate()'s rows, estimates included: one estimate policy, whose companions are lanes here.
class LaneRuns {
 public:
  LaneRuns(const MethodInfo& method, const std::vector<batch::Member>& members, const std::vector<Scene>& scenes,
           const std::atomic<bool>* cancel)
      : method_(method), members_(members), scenes_(scenes), cancel_(cancel) {}

  /// Lane k's run from `from` (its start, or its start moved by a rounding either way) as `how`.
  BodyResult run(std::size_t k, const Body& from, const Advance& how, const Options& o) {
    const auto* f = std::get_if<FixedSteps>(&how);
    if (f == nullptr) throw Error("a batch's lanes run by fixed steps");  // their methods' only way (plan_units)
    const std::optional<double> way = way_of(k, from.s0);
    if (!way) return lanes(k, k + 1, *f, from.s0, o).front();  // not a start the batch shares: this lane alone
    const Key key{f->h, f->steps, *way, o.max_energy_error, o.track_invariants};
    auto found = done_.find(key);
    if (found == done_.end() || !found->second[k]) {
      std::vector<std::optional<BodyResult>> lane(members_.size());
      std::vector<BodyResult> ran = lanes(k, members_.size(), *f, std::nullopt, o, *way);
      for (std::size_t j = k; j < members_.size(); ++j) lane[j] = std::move(ran[j - k]);
      found = done_.insert_or_assign(key, std::move(lane)).first;
    }
    return std::move(*std::exchange(found->second[k], std::nullopt));
  }

 private:
  using Key = std::tuple<double, long, double, double, bool>;  // h, steps, the rounding's way, energy bound, invariants

  /// The way (0, +1, -1) start_moved_by_rounding moved lane k's start to s; nullopt: none of them.
  std::optional<double> way_of(std::size_t k, const State& s) const {
    for (const double way : {0.0, 1.0, -1.0}) {
      const State moved = way == 0.0 ? members_[k].s0 : detail::start_moved_by_rounding(members_[k].s0, way);
      if (moved.R == s.R && moved.v == s.v && moved.w == s.w) return way;
    }
    return std::nullopt;
  }

  /// Lanes [first, last) as `how`, each from `start` or from its own start moved `way`, judged as integrate() judges.
  std::vector<BodyResult> lanes(std::size_t first, std::size_t last, const FixedSteps& how, const std::optional<State>& start,
                                const Options& o, double way = 0.0) const {
    std::vector<batch::Member> moved(members_.begin() + static_cast<long>(first), members_.begin() + static_cast<long>(last));
    for (batch::Member& m : moved)
      m.s0 = start ? *start : way == 0.0 ? m.s0 : detail::start_moved_by_rounding(m.s0, way);
    std::vector<RunResult> runs = batch::run(method_, moved, how, 0, cancel_);
    std::vector<BodyResult> out(moved.size());
    for (std::size_t j = 0; j < out.size(); ++j) {
      out[j].method = &method_;
      if (runs.empty()) {  // stopped on request
        out[j].outcome = Outcome::failed;
        out[j].reason = kStoppedOnRequest;
        continue;
      }
      out[j].run = std::move(runs[j]);
      detail::judge(out[j], scenes_[first + j].centres, o);
    }
    return out;
  }

  const MethodInfo& method_;
  const std::vector<batch::Member>& members_;
  const std::vector<Scene>& scenes_;
  const std::atomic<bool>* cancel_;
  std::map<Key, std::vector<std::optional<BodyResult>>> done_;
};

/// The rows of a batch: its lanes run as one batch, then each estimated and settled by integrate()'s policy
/// (estimate_and_settle), its companions lanes of batches too (LaneRuns).
void batch_rows(std::vector<SweepRow>& rows, const SweepSpec& spec, const MethodInfo& method,
                const std::vector<batch::Member>& members, const std::vector<Scene>& scenes) {
  const Advance how = point_advance(spec, method, rows.front().point);
  const Options options = sweep_options(spec);
  LaneRuns lanes(method, members, scenes, spec.cancel);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const Body& body = scenes[k].bodies.front();
    BodyResult r = lanes.run(k, body, how, options);
    const detail::Rerun rerun{[&lanes, k](const Body& from, const Advance& a, const Options& o) { return lanes.run(k, from, a, o); },
                              false};
    detail::estimate_and_settle(r, body, scenes[k].centres, how, options, rerun);
    rows[k] = result_row(std::move(rows[k]), std::move(r));
  }
}

/// A grid point's thesis parameters, and the asymptotic data its axes give (NaN: not given), solved in.
struct PointData {
  SceneParams params;
  double b = Scattering::kNaN, v_inf = Scattering::kNaN, arrival = Scattering::kNaN;
};

PointData point_data(const SweepSpec& spec, const std::vector<double>& point) {
  PointData d{spec.base};
  for (std::size_t a = 0; a < spec.axes.size(); ++a) {
    const std::string& name = spec.axes[a].param;
    if (name == "b") d.b = point[a];
    else if (name == "v_inf") d.v_inf = point[a];
    else if (name == "arrival_phase") d.arrival = point[a];
    else if (name != "h") scene_field(d.params, name) = point[a];
  }
  if (!(std::isnan(d.b) && std::isnan(d.v_inf) && std::isnan(d.arrival))) d.params = with_asymptotic_data(d.params, d.b, d.v_inf, d.arrival);
  return d;
}

/// The start distance's part of a row's encounter error: the grid point's scene from twice its start
/// distance (thesis_scene_twice_as_far: the point's data b, v_inf, arrival phase solved for again, the
/// rest kept), run to its departure by auto (twice_as_far_tol), or beside the row's run where far legs serve
/// both (twice_as_far_beside).
struct RowFar {
  std::optional<PointData> d;  ///< the point's data, solved once for the far scene and the limit's rule
  std::function<Expected<Scene>()> far;
  bool at_limit = false;
  Options options;
};
RowFar row_far(const SweepSpec& spec, const std::vector<double>& point) {
  RowFar f;
  if (spec.scene_text.empty()) {
    f.d = point_data(spec, point);
    f.far = [d = *f.d] { return thesis_scene_twice_as_far(d.params, d.b, d.v_inf, d.arrival); };
    f.at_limit = answers_at_limit(f.d->b, f.d->v_inf);
  }
  f.options.track_invariants = false;
  f.options.cancel = spec.cancel;
  return f;
}

/// The row of a run with its encounter (SweepSpec::scattering): integrate_encounter_checked (far legs where
/// auto runs it) with the encounter's events (encounter_options: it stops at the departure, the sweep's end
/// the latest), measured by measure_encounter; an encounter that did not finish by the end is the row's
/// outcome (incomplete).
SweepRow encounter_row(SweepRow row, const MethodInfo* method, const Scene& scene, const Advance& how,
                       const SweepSpec& spec) {
  const Body& body = scene.bodies.front();
  const Options options = encounter_options(body, scene.centres, sweep_options(spec), true);
  const RowFar f = row_far(spec, row.point);
  std::optional<TwiceAsFar> twice = twice_as_far_beside(f.far, f.at_limit, body, scene.centres, spec.accuracy, f.options);
  TwiceAsFar* beside = twice ? &*twice : nullptr;
  BodyResult r = detail::integrate_encounter_checked(body, scene.centres, method, how, options, beside);  // checked by validate_sweep
  if (!ran(r.outcome)) return result_row(std::move(row), std::move(r));
  Encounter e = measure_encounter(body, scene.centres, r, options.events);
  if (e.outcome == Outcome::ok && r.outcome == Outcome::ok)
    row.start_distance_force_evals = add_start_distance(e, body, f.far, spec.accuracy, r.error.for_orbit(),
                                                        "a scene file's body has no thesis start distance to double", f.options,
                                                        f.at_limit, &r, beside);
  row.r_min = e.r_min;
  row.t_min = e.t_min;
  row.r_min_error = e.r_min_error;
  row.t_min_error = e.t_min_error;
  row.asymptote_error = e.asymptote_error;
  row.start_distance_error = e.start_distance_error;
  row.time_delay_error = e.time_delay_error;
  row.deflection_error = e.deflection_error;
  row = result_row(std::move(row), std::move(r));
  if (row.outcome != Outcome::ok) return row;
  row.scattering = e.scattering;
  if (e.outcome != Outcome::ok) {
    row.outcome = e.outcome;
    row.reason = e.reason;
  }
  return row;
}

}  // namespace

std::size_t task_count(const SweepSpec& spec) {
  double n = static_cast<double>(spec.methods.size());
  for (const Axis& a : spec.axes) n *= static_cast<double>(a.values.size());
  if (n > 1e9) throw Error("the sweep has more than 1e9 (grid point, method) runs");
  return static_cast<std::size_t>(n);
}

std::vector<double> grid_point(const SweepSpec& spec, std::size_t p) {
  std::vector<double> point(spec.axes.size());
  for (std::size_t a = spec.axes.size(); a-- > 0;) {
    const std::size_t n = spec.axes[a].values.size();
    point[a] = spec.axes[a].values[p % n];
    p /= n;
  }
  return point;
}

SceneParams point_params(const SweepSpec& spec, const std::vector<double>& point) { return point_data(spec, point).params; }

SweepSpec with_scene_file(SweepSpec spec, std::string text, std::string origin) {
  const Scene scene = parse_scene(text, origin);
  for (const Axis& a : spec.axes)
    if (a.param == kBodyAxis) throw Error("the axis 'body' is the sweep's own (one row per body of the scene)");
  spec.scene_text = std::move(text);
  spec.scene_origin = std::move(origin);
  if (scene.bodies.size() > 1) {
    Axis bodies{kBodyAxis, {}};
    for (std::size_t i = 1; i <= scene.bodies.size(); ++i) bodies.values.push_back(static_cast<double>(i));
    spec.axes.push_back(std::move(bodies));
  }
  return spec;
}

Scene point_scene(const SweepSpec& spec, const std::vector<double>& point) {
  if (spec.scene_text.empty()) return thesis_scene(point_params(spec, point));
  std::vector<SceneValue> set;
  std::size_t body = 0;
  for (std::size_t a = 0; a < spec.axes.size(); ++a) {
    const std::string& name = spec.axes[a].param;
    if (name == kBodyAxis) body = static_cast<std::size_t>(point[a]);
    else if (name != "h") set.push_back({name, point[a]});
  }
  Scene scene = parse_scene(spec.scene_text, spec.scene_origin, set);
  if (body > 0) scene.bodies = {scene.bodies.at(body - 1)};
  return scene;
}

FixedSteps sweep_steps(double h, long steps, double t_end, ForceLaw law) {
  require_positive(h, "the step h");
  if (law == ForceLaw::thesis_code) return thesis_code_steps(h, steps, t_end);
  if (t_end > 0.0) return fixed_steps_to(t_end, h);
  return {h, require_count(steps, "the number of steps")};
}

Advance to_common_end(const MethodInfo& method, const FixedSteps& f, double tol) {
  // A fixed-step method keeps the grid it was given; the others run to its end.
  const Advance how = advance_of(method, {.step = f.h, .end = f.h * static_cast<double>(f.steps), .tol = tol});
  return std::holds_alternative<FixedSteps>(how) ? Advance(f) : how;
}

Advance point_advance(const SweepSpec& spec, const MethodInfo& method, const std::vector<double>& point) {
  return point_advance(spec, &method, point);
}

Advance point_advance(const SweepSpec& spec, const MethodInfo* m, const std::vector<double>& point) {
  if (!m && !spec.accuracy) throw Error("method auto needs the accuracy mode (SweepSpec::accuracy: the tolerance to deliver)");
  if (spec.accuracy && (!m || !takes_tolerance_per_step(*m))) {
    if (spec.t_end > 0.0 || !spec.scattering) return Accuracy{*spec.accuracy, spec.t_end};
    // An encounter without an end: its span (the departure event stops the run), as simulate takes it.
    const Scene scene = point_scene(spec, point);
    return Accuracy{*spec.accuracy, encounter_span(scene.bodies.front(), scene.centres)};
  }
  return to_common_end(*m, sweep_steps(point_h(spec, point), spec.steps, spec.t_end, spec.base.law), spec.tol);
}

std::vector<const MethodInfo*> sweep_methods_named(std::string_view list) {
  std::vector<const MethodInfo*> ms;
  std::string named;
  for (std::size_t start = 0; start <= list.size();) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    const std::string_view name = list.substr(start, comma - start);
    if (name == "auto") ms.push_back(nullptr);
    else if (!name.empty()) named.append(named.empty() ? "" : ",").append(name);
    start = comma + 1;
  }
  if (!named.empty())
    for (const MethodInfo* m : methods_named(named)) ms.push_back(m);
  if (ms.empty()) throw Error("the method list is empty");
  return ms;
}

bool has_auto(const SweepSpec& spec) { return std::find(spec.methods.begin(), spec.methods.end(), nullptr) != spec.methods.end(); }

void settle_auto(SweepSpec& spec) {
  if (!has_auto(spec) || spec.accuracy) return;
  if (spec.methods.size() > 1)
    throw Error("auto chooses the method for an accuracy: give the accuracy (--accuracy, accuracy=) for a sweep that also "
                "names methods, or list auto alone (its accuracy is then the tolerance tol, " + fmt(spec.tol) + ")");
  spec.accuracy = spec.tol;
  if (!(spec.t_end > 0.0) && spec.steps > 0 && !spec.scattering) {
    spec.t_end = spec.h * static_cast<double>(spec.steps);  // the end time the steps asked for reach
    spec.steps = 0;
  }
}

std::string point_label(const SweepSpec& spec, const std::vector<double>& point) {
  std::string s;
  for (std::size_t a = 0; a < spec.axes.size(); ++a) {
    if (a) s += ", ";
    s.append(spec.axes[a].param).append(" = ").append(fmt(point[a]));
  }
  return s;
}

void fix_asymptotic_datum(SweepSpec& spec, const std::string& datum, double value, const std::string& named_as) {
  const bool positive = datum != "arrival_phase";  // b and v_inf; a phase is any finite number
  if (!(std::isfinite(value) && (value > 0.0 || !positive)))
    throw Error(named_as + " must be a finite number" + (positive ? " > 0" : ""));
  if (std::any_of(spec.axes.begin(), spec.axes.end(), [&datum](const Axis& a) { return a.param == datum; }))
    throw Error(named_as + " is fixed and varied at once");
  spec.axes.push_back(Axis{datum, {value}});
}

void validate_sweep_rules(const SweepSpec& spec) {
  if (spec.methods.empty()) throw Error("the method list is empty");
  if (has_auto(spec) && !spec.accuracy)
    throw Error("method auto needs the accuracy mode (SweepSpec::accuracy: the tolerance to deliver)");
  check_energy_bound(spec.max_energy_error);
  check_error_bound(spec.max_error);
  if (spec.axes.empty()) throw Error("the sweep has no varied parameter");
  // 0: not given (the steps count); a sweep runs forwards (Python's sweep(t_end=-20) read "0 steps").
  if (spec.t_end != 0.0) require_positive(spec.t_end, "the end time t_end");
  const bool file = !spec.scene_text.empty();
  for (const Axis& a : spec.axes) {
    if (a.param == "h" || (file && a.param == kBodyAxis)) continue;
    if (file && !is_scene_key(a.param))
      throw Error("a sweep over a scene file varies its keys (centre2.A, centre1.position.x, body.B, bodyK.d, NAME.KEY), "
                  "not '" + a.param + "'");
    if (!file && is_scene_key(a.param)) throw Error("the axis '" + a.param + "' is a scene file's key: give the scene");
    if (!file && std::find(sweep_parameters().begin(), sweep_parameters().end(), a.param) == sweep_parameters().end())
      throw Error(unknown_name("parameter", a.param, sweep_parameters()));
  }
  if (spec.accuracy) {
    check_tolerance(*spec.accuracy);
    if (!(spec.t_end > 0.0) && !spec.scattering)
      throw Error("the accuracy mode delivers its tolerance at an end time: give t_end");
    for (const Axis& a : spec.axes)
      if (a.param == "h") throw Error("the accuracy mode chooses the step: h cannot be a varied parameter");
  }
  for (const Axis& a : spec.axes) {
    if (a.values.empty()) throw Error("the sweep has no values of " + a.param);
    // NaN stands for "not given" among the asymptotic data: a NaN value would compute another scene.
    for (double v : a.values)
      if (a.param == "b" || a.param == "v_inf" || a.param == "h") require_positive(v, "the sweep's values of " + a.param);
      else if (!std::isfinite(v)) throw Error("the sweep's values of " + a.param + " must be finite numbers, got " + fmt(v));
  }
  for (const Axis& a : spec.axes)
    for (const Axis& other : spec.axes)
      if ((a.param == "b" && other.param == "d") || (a.param == "v_inf" && other.param == "K1") ||
          (a.param == "arrival_phase" && other.param == "phase"))
        throw Error("the sweep varies " + a.param + " and " + other.param + ", which it solves for " + a.param);
  // Every step of the axis h makes a run (at most 1e13 steps): a calibration averages over them all.
  for (const Axis& a : spec.axes)
    if (a.param == "h")
      for (double h : a.values) sweep_steps(h, spec.steps, spec.t_end, spec.base.law);
}

std::size_t sweep_points(const SweepSpec& spec) { return task_count(spec) / spec.methods.size(); }

void validate_sweep_points(const SweepSpec& spec, std::size_t from, std::size_t to) {
  // Every point's scene and every method's way of advancing there, checked once for the sweep.
  for (std::size_t p = from; p < to; ++p) {
    const std::vector<double> point = grid_point(spec, p);
    try {
      validate(point_scene(spec, point));
      for (const MethodInfo* m : spec.methods) check(point_advance(spec, m, point));
    } catch (const Error& e) {
      throw Error(point_label(spec, point) + ": " + e.what());
    }
  }
}

void validate_sweep(const SweepSpec& spec) {
  validate_sweep_rules(spec);
  validate_sweep_points(spec, 0, sweep_points(spec));
}

namespace {

/// A planned step is at most this many times the pilot's delivered step: a pilot delivered far below its
/// target (its estimate 1e-3 tol, where a coarser run of the ladder was the answer) predicts a step the
/// estimate of one run does not extrapolate to.
constexpr double kPlanMaxGain = 2.0;

/// The pilots of an axis of n values: ceil(sqrt(n)), the j-th at the middle of its share of the axis.
std::size_t axis_pilots(std::size_t n) { return static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n)))); }
std::size_t pilot_index(std::size_t n, std::size_t j) { return (2 * j + 1) * n / (2 * axis_pilots(n)); }

/// The task of the pilot nearest to grid point p, in the column `column` of M methods.
std::size_t nearest_pilot(const SweepSpec& spec, std::size_t p, std::size_t column) {
  std::vector<std::size_t> index(spec.axes.size());
  for (std::size_t a = spec.axes.size(); a-- > 0; p /= spec.axes[a].values.size()) index[a] = p % spec.axes[a].values.size();
  std::size_t pilot = 0;
  for (std::size_t a = 0; a < spec.axes.size(); ++a) {
    const std::size_t n = spec.axes[a].values.size();
    pilot = pilot * n + pilot_index(n, std::min(index[a] * axis_pilots(n) / n, axis_pilots(n) - 1));
  }
  return pilot * spec.methods.size() + column;
}

std::size_t auto_column(const SweepSpec& spec) {
  return static_cast<std::size_t>(std::find(spec.methods.begin(), spec.methods.end(), nullptr) - spec.methods.begin());
}

/// `how` (an auto row's Accuracy) starts at the plan's step of the row's nearest pilot where auto chooses the
/// pilot's method here. Returns that pilot's task, or nothing where the row is not planned.
std::optional<std::size_t> start_as_planned(const MapPlan& plan, const SweepSpec& spec, const Scene& scene, std::size_t task,
                                            Advance& how) {
  auto* a = std::get_if<Accuracy>(&how);
  const auto it = plan.steps.find(nearest_pilot(spec, task / spec.methods.size(), auto_column(spec)));
  if (!a || it == plan.steps.end() || !(it->second.first_step > 0.0)) return std::nullopt;
  try {
    if (&detail::choose_method_for(scene.bodies.front(), scene.centres, *spec.accuracy, nullptr) != it->second.method)
      return std::nullopt;
  } catch (const Error&) {
    return std::nullopt;  // the row's own search says why
  }
  a->first_step = it->second.first_step;
  return it->first;
}

}  // namespace

MapPlan plan_map(const SweepSpec& spec, unsigned threads) {
  MapPlan plan;
  if (!has_auto(spec) || !spec.accuracy) return plan;
  std::vector<std::size_t> pilots{0};  // grid points, built axis by axis
  for (const Axis& axis : spec.axes) {
    std::vector<std::size_t> longer;
    for (std::size_t p : pilots)
      for (std::size_t j = 0; j < axis_pilots(axis.values.size()); ++j)
        longer.push_back(p * axis.values.size() + pilot_index(axis.values.size(), j));
    pilots = std::move(longer);
  }
  for (std::size_t& p : pilots) p = p * spec.methods.size() + auto_column(spec);
  std::vector<SweepRow> rows(pilots.size());
  parallel_for(pilots.size(), threads, [&](std::size_t k) { rows[k] = run_sweep_unit_rows(spec, {pilots[k]}).front(); });
  for (std::size_t k = 0; k < pilots.size(); ++k) {
    const SweepRow& row = rows[k];
    MapPlan::Step step{row.method, 0.0};
    if (row.outcome == Outcome::ok && row.method && row.accuracy && row.accuracy->err_estimate > 0.0 && row.accuracy->h_chosen > 0.0) {
      const double order = effective_order(*row.method, point_scene(spec, row.point).bodies.front());
      const double aim = bodypoint::kTargetShare * *spec.accuracy / row.accuracy->err_estimate;
      step.first_step = row.accuracy->h_chosen * (order > 0.0 ? std::clamp(std::pow(aim, 1.0 / order), 1.0, kPlanMaxGain) : 1.0);
    }
    plan.steps.emplace(pilots[k], step);
    plan.pilots.emplace(pilots[k], std::move(rows[k]));
  }
  return plan;
}

std::vector<SweepRow> run_sweep_unit_rows(const SweepSpec& spec, const std::vector<std::size_t>& unit, const MapPlan* plan) {
  const std::size_t M = spec.methods.size();
  const MethodInfo* asked = spec.methods[unit.front() % M];  // nullptr: auto
  std::vector<SweepRow> rows;
  std::vector<batch::Member> members;
  std::vector<Scene> scenes;
  for (std::size_t i : unit) {
    SweepRow row;
    row.task = i;
    row.point = grid_point(spec, i / M);
    row.method = asked;
    row.automatic = !asked;
    rows.push_back(std::move(row));
    scenes.push_back(point_scene(spec, rows.back().point));
    members.push_back({scenes.back().bodies.front().p, scenes.back().bodies.front().s0, scenes.back().centres.front().A});
  }
  if (unit.size() > 1) {  // a batch: one method, one step (plan_units), lanes that accept it
    batch_rows(rows, spec, *asked, members, scenes);
    return rows;
  }
  SweepRow& row = rows.front();
  if (plan && !asked)
    if (const auto pilot = plan->pilots.find(row.task); pilot != plan->pilots.end()) return {pilot->second};
  const Scene& scene = scenes.front();
  Advance how = point_advance(spec, asked, row.point);
  const std::optional<std::size_t> pilot = plan && !asked ? start_as_planned(*plan, spec, scene, row.task, how) : std::nullopt;
  if (spec.scattering) row = encounter_row(std::move(row), asked, scene, how, spec);
  else row = result_row(std::move(row), detail::integrate_checked(scene.bodies.front(), scene.centres, asked, how, sweep_options(spec)));
  if (pilot && row.accuracy) {
    const std::string planned = "; its first step planned from the row at " + point_label(spec, grid_point(spec, *pilot / M));
    row.accuracy->basis += planned;
    row.error.basis += planned;
  }
  return rows;
}

/// A batch of vector lanes does not poll SweepSpec::cancel: a cancellable sweep batches only rows of at
/// most this many steps (a batch of lp-y4 with its companions, measured: about 0.6 us per step, so
/// 0.6 s), and runs longer rows alone, where every kPollStride steps are polled.
constexpr double kMaxUnpolledBatchSteps = 1e6;

std::vector<std::vector<std::size_t>> plan_units(const SweepSpec& spec, const std::vector<std::size_t>& todo, bool simd) {
  std::vector<std::vector<std::size_t>> units;
  const std::size_t M = spec.methods.size(), lanes = simd && !spec.scattering && !spec.accuracy ? batch::width() : 1;
  std::map<std::pair<std::size_t, double>, std::vector<std::size_t>> open;  // (method, h) -> a filling batch
  for (std::size_t i : todo) {
    if (lanes < 2) {  // the accuracy mode (auto's rows among them), encounters, no SIMD: each row alone
      units.push_back({i});
      continue;
    }
    const MethodInfo& method = *spec.methods[i % M];
    const std::vector<double> point = grid_point(spec, i / M);
    const Scene scene = point_scene(spec, point);
    if (!batch::accepts(method, scene.bodies.front(), scene.centres) ||
        (spec.cancel && static_cast<double>(std::get<FixedSteps>(point_advance(spec, method, point)).steps) >
                            kMaxUnpolledBatchSteps)) {
      units.push_back({i});
      continue;
    }
    auto& filling = open[{i % M, point_h(spec, point)}];
    filling.push_back(i);
    if (filling.size() == lanes) units.push_back(std::exchange(filling, {}));
  }
  for (auto& [key, rest] : open)
    if (!rest.empty()) units.push_back(rest);
  return units;
}

std::size_t shard_of(const SweepSpec& spec, std::size_t task, std::size_t shards) {
  const std::size_t M = spec.methods.size();
  return (task / M + task % M) % std::max<std::size_t>(shards, 1);
}

void run_sweep_tasks(const SweepSpec& spec, const std::vector<std::size_t>& todo, const SweepRunner& runner) {
  if (!runner.validated) validate_sweep(spec);
  // auto's rows start at the map's plan (its pilots run first); a pilot this runner was asked for is its row.
  const MapPlan plan = todo.empty() ? MapPlan{} : plan_map(spec, runner.threads);
  std::vector<std::size_t> rest;
  for (std::size_t i : todo) {
    const auto pilot = plan.pilots.find(i);
    if (pilot == plan.pilots.end()) rest.push_back(i);
    else if (runner.on_row) runner.on_row(SweepRow(pilot->second));
  }
  const auto units = plan_units(spec, rest, runner.simd);
  std::atomic<std::size_t> next{0};
  std::mutex mutex;  // on_row and the first error
  std::exception_ptr error;
  auto worker = [&] {
    for (std::size_t k; !(runner.stop && runner.stop()) && (k = next++) < units.size();) {
      std::vector<SweepRow> rows = run_sweep_unit_rows(spec, units[k], &plan);
      std::lock_guard<std::mutex> lock(mutex);
      try {
        if (runner.on_row)
          for (SweepRow& row : rows) runner.on_row(std::move(row));
      } catch (...) {  // e.g. the caller's journal cannot be written: stop handing out units
        if (!error) error = std::current_exception();
        next = units.size();
      }
    }
  };
  {
    // Threads beside this one: none for a single unit or none at all (every row a pilot).
    const WorkerThreads pool(static_cast<unsigned>(std::min<std::size_t>(runner.threads, std::max<std::size_t>(units.size(), 1))) - 1, worker);
    worker();
  }
  if (error) std::rethrow_exception(error);
}

std::vector<SweepRow> run_sweep_rows(const SweepSpec& spec, unsigned threads,
                                     const std::function<void(std::size_t, std::size_t)>& progress) {
  std::vector<std::size_t> all(task_count(spec));
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  std::vector<SweepRow> rows(all.size());
  SweepRunner runner;
  runner.threads = std::max(1u, threads);
  std::size_t done = 0;
  runner.on_row = [&rows, &done, &progress, total = all.size()](SweepRow&& r) {  // under the runner's lock
    rows[r.task] = std::move(r);
    if (progress) progress(++done, total);
  };
  const auto cancelled = [&spec] { return spec.cancel && spec.cancel->load(std::memory_order_relaxed); };
  runner.stop = cancelled;
  run_sweep_tasks(spec, all, runner);
  if (cancelled()) throw Error(kStoppedOnRequest);
  return rows;
}

}  // namespace bodypoint
