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

/// Whether a lane's run ended so that it has an estimate (estimate_error of integrate(): ok, or a flag).
bool estimable(Outcome o) { return o == Outcome::ok || o == Outcome::unresolved || o == Outcome::inaccurate; }

/// integrate()'s rounding draws (estimate/rounding.cpp, add_rounding_draws) for a batch's lanes: for each lane with
/// an estimate in `drawn` (nullptr: none; decided before the draws, as integrate() does),
/// ErrorEstimate::kRoundingDraws - 1 more batches, the k-th advancing as `how(k)` from starts moved by a
/// rounding, what each lane's `finals` differs from them by added, the sum then taken as a bound.
void lane_rounding_draws(const MethodInfo& method, const std::vector<batch::Member>& members,
                         const std::function<Advance(int)>& how, const std::vector<const State*>& finals,
                         const std::vector<ErrorEstimate*>& drawn, const std::string& what) {
  if (std::all_of(drawn.begin(), drawn.end(), [](const ErrorEstimate* e) { return e == nullptr; })) return;
  std::vector<batch::Member> moved = members;
  for (int draw = 1; draw < ErrorEstimate::kRoundingDraws; ++draw) {
    for (std::size_t k = 0; k < members.size(); ++k)
      moved[k].s0 = detail::start_moved_by_rounding(members[k].s0, detail::rounding_way(draw));
    const auto other = batch::run(method, moved, std::get<FixedSteps>(how(draw)));
    for (std::size_t k = 0; k < members.size(); ++k)
      if (drawn[k] != nullptr)
        detail::add_rounding_spread(*drawn[k], *finals[k], other[k].final, other[k].force_evals, other[k].wall_s, what);
  }
  for (ErrorEstimate* e : drawn)
    if (e != nullptr) detail::bound_from_draws(*e);
}

/// As integrate() (estimate/coarse.cpp): the lanes whose trusted coarse estimate asks (asks_second_coarse)
/// get a second coarse batch, the coarse batch's own coarse companion from the same moved starts; a lane whose
/// three runs do not observe the order the estimate assumes is left to the fine companions, the batch's cost
/// counted in `cost` as the coarse batch's is.
void second_coarse_batch(const MethodInfo& method, const detail::CoarseCompanion& c, const std::vector<batch::Member>& moved,
                         const std::vector<Scene>& scenes, const std::vector<RunResult>& results,
                         const std::vector<RunResult>& coarse, std::vector<std::optional<ErrorEstimate>>& out,
                         std::vector<ErrorEstimate>& cost) {
  // As integrate(): a lane asks to keep its pair (asks_second_coarse) or to sharpen it (sharpened_by_second_coarse).
  enum class Second { none, asks, sharpens };
  std::vector<Second> second(out.size(), Second::none);
  double max_ratio = ErrorEstimate::kStepRatio;
  bool any = false;
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (!out[k]) continue;
    const Body& body = scenes[k].bodies.front();
    second[k] = detail::asks_second_coarse(method, body, scenes[k].centres, *out[k]) ? Second::asks
                : detail::sharpened_by_second_coarse(method, body, scenes[k].centres, c, *out[k]) ? Second::sharpens
                                                                                                  : Second::none;
    if (second[k] != Second::none)
      any = true, max_ratio = std::min(max_ratio, detail::coarse_ratio_limit(method, scenes[k].centres, coarse[k]));
  }
  if (!any) return;
  const auto c2 = detail::coarse_companion(method, c.how, std::get<FixedSteps>(c.how).steps, max_ratio);
  if (!c2) return;
  const auto y = batch::run(method, moved, std::get<FixedSteps>(c2->how));
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (second[k] == Second::none) continue;
    const bool ok = assess(y[k], checks_for(method, scenes[k].centres, detail::kCoarseEnergyBound)).outcome == Outcome::ok;
    ErrorEstimate trial = *out[k];
    trial.force_evals += y[k].force_evals;
    trial.wall_s += y[k].wall_s;
    if (ok && detail::observed_order_agrees(method, scenes[k].bodies.front(), c, *c2, results[k].final, coarse[k].final,
                                            y[k].final, trial)) {
      *out[k] = std::move(trial);
    } else if (second[k] == Second::sharpens) {  // the capped estimate stands
      out[k]->force_evals = trial.force_evals, out[k]->wall_s = trial.wall_s;
    } else {
      cost[k].force_evals += y[k].force_evals;
      cost[k].wall_s += y[k].wall_s;
      out[k].reset();
    }
  }
}

/// The lanes' estimates from the coarse companion batch (estimate.hpp, CoarseCompanion), as integrate()
/// makes them: nullopt for a lane the fine companions decide (flagged, or its coarse estimate not trusted),
/// whose estimate then counts the coarse lane's cost in `cost` as integrate() does.
std::vector<std::optional<ErrorEstimate>> coarse_estimates(const MethodInfo& method, const FixedSteps& how,
                                                           const std::vector<batch::Member>& members,
                                                           const std::vector<Scene>& scenes,
                                                           const std::vector<RunResult>& results,
                                                           const std::vector<Health>& health,
                                                           std::vector<ErrorEstimate>& cost,
                                                           std::vector<std::optional<double>>& coarse_side) {
  std::vector<std::optional<ErrorEstimate>> out(members.size());
  double max_ratio = ErrorEstimate::kStepRatio;  // one coarse batch: the ratio every lane's steps allow
  for (std::size_t k = 0; k < members.size(); ++k)
    max_ratio = std::min(max_ratio, detail::coarse_ratio_limit(method, scenes[k].centres, results[k]));
  const auto c = detail::coarse_companion(method, how, how.steps, max_ratio);
  if (!c) return out;
  std::vector<batch::Member> moved = members;
  for (batch::Member& m : moved) m.s0 = detail::start_moved_by_rounding(m.s0);
  const auto coarse = batch::run(method, moved, std::get<FixedSteps>(c->how));
  for (std::size_t k = 0; k < members.size(); ++k) {
    cost[k].force_evals = coarse[k].force_evals;
    cost[k].wall_s = coarse[k].wall_s;
    if (health[k].outcome != Outcome::ok && health[k].outcome != Outcome::inaccurate) continue;
    if (assess(coarse[k], checks_for(method, scenes[k].centres, detail::kCoarseEnergyBound)).outcome != Outcome::ok) continue;
    if (!(coarse[k].final.R.allFinite() && coarse[k].final.v.allFinite())) continue;
    coarse_side[k] = detail::coarse_side_of(method, scenes[k].bodies.front(), *c, results[k].final, coarse[k].final);
    out[k] = detail::coarse_estimate(method, scenes[k].bodies.front(), scenes[k].centres, *c, results[k].final,
                                     coarse[k].final, results[k].steps);
    if (out[k]) out[k]->force_evals = coarse[k].force_evals, out[k]->wall_s = coarse[k].wall_s;
  }
  second_coarse_batch(method, *c, moved, scenes, results, coarse, out, cost);
  // As integrate(): lanes whose coarse estimate is at the rounding level add more draws of it, coarse
  // batches off the run's grid.
  std::vector<const State*> finals(members.size());
  std::vector<ErrorEstimate*> drawn(members.size(), nullptr);
  for (std::size_t k = 0; k < members.size(); ++k) {
    finals[k] = &results[k].final;
    if (out[k] && detail::at_rounding_level(*out[k])) drawn[k] = &*out[k];
  }
  lane_rounding_draws(method, members, [&c](int k) { return detail::coarse_draw(*c, k); }, finals, drawn,
                      detail::coarse_draw_text(*c));
  return out;
}

/// As integrate(): a batch's flagged lanes that the second companion did not confirm get a third companion,
/// one level finer again (estimate.hpp, confirm_deeper).
void confirm_deeper_lanes(std::vector<SweepRow>& rows, const SweepSpec& spec, const MethodInfo& method,
                          const std::vector<batch::Member>& members, const FixedSteps& how,
                          const std::vector<std::optional<ErrorEstimate>>& by_coarse,
                          const std::vector<RunResult>& companions, const std::vector<RunResult>& second) {
  const auto deeper = [&](std::size_t k) {
    return spec.estimate_error && !by_coarse[k] && rows[k].outcome == Outcome::unresolved && !rows[k].error.confirmed &&
           rows[k].error.known();
  };
  bool any_deeper = false;
  for (std::size_t k = 0; k < rows.size(); ++k) any_deeper = any_deeper || deeper(k);
  if (!any_deeper) return;
  const auto third = batch::run(method, members, detail::fixed_companion(how, 3));
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (!deeper(k)) continue;
    rows[k].error.force_evals += third[k].force_evals;
    rows[k].error.wall_s += third[k].wall_s;
    detail::confirm_deeper(rows[k].error, rows[k].result.final, companions[k].final, second[k].final, third[k].final);
  }
}

/// The last steps of a batch's estimates, as integrate() takes them: lanes at the rounding level add draws of
/// it, a second companion bounds the fine pairs it was asked for, and every lane is settled (flags, bounds).
void settle_lanes(std::vector<SweepRow>& rows, const SweepSpec& spec, const MethodInfo& method,
                  const std::vector<batch::Member>& members, const std::vector<Scene>& scenes, const FixedSteps& how,
                  const std::vector<std::optional<ErrorEstimate>>& by_coarse, const std::vector<std::optional<double>>& coarse_side,
                  const std::vector<RunResult>& companions, const std::vector<RunResult>& second) {
  // As integrate(): lanes whose fine estimate is at the rounding level add more draws of it, repeats off
  // their grid (estimate.hpp).
  std::vector<const State*> finals(rows.size());
  std::vector<ErrorEstimate*> drawn(rows.size(), nullptr);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    finals[k] = &rows[k].result.final;
    if (spec.estimate_error && !by_coarse[k] && detail::at_rounding_level(rows[k].error)) drawn[k] = &rows[k].error;
  }
  lane_rounding_draws(method, members, [&how](int k) { return detail::off_grid(how, k); }, finals, drawn,
                      detail::kRepeatRoundingDraw);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (!spec.estimate_error || by_coarse[k] || !estimable(rows[k].outcome) || second.empty()) continue;
    ErrorEstimate& e = rows[k].error;
    const bool check = detail::checks_fine_pair(method, scenes[k].centres, rows[k].result, coarse_side[k], e.value);
    if (rows[k].outcome != Outcome::unresolved) {  // a flagged lane counted its second companion above
      if (!check && how.steps >= detail::kFewSteps) continue;
      e.force_evals += second[k].force_evals;
      e.wall_s += second[k].wall_s;
    }
    if (second[k].final.R.allFinite() && second[k].final.v.allFinite())
      detail::bound_by_second(e, method, scenes[k].bodies.front(), how.steps, check, rows[k].result.final,
                              companions[k].final, second[k].final);
  }
  for (std::size_t k = 0; k < rows.size(); ++k)
    detail::settle(rows[k].outcome, rows[k].reason, rows[k].warnings, rows[k].error, spec.max_error, spec.max_energy_error,
                   detail::final_energy_error(scenes[k].bodies.front(), scenes[k].centres, rows[k].result.final));
}

/// The rows of a batch: its lanes, judged by assess() and, with SweepSpec::estimate_error, by the
/// estimate from a coarse companion batch or, where that is not trusted, from companion batches at h/2
/// (and h/4 for flagged lanes): the same kernel and the same rule as integrate() alone (estimate/).
void batch_rows(std::vector<SweepRow>& rows, const SweepSpec& spec, const MethodInfo& method,
                const std::vector<batch::Member>& members, const std::vector<Scene>& scenes) {
  const FixedSteps how = std::get<FixedSteps>(point_advance(spec, method, rows.front().point));
  auto results = batch::run(method, members, how);
  std::vector<Health> health;
  for (std::size_t k = 0; k < rows.size(); ++k)
    health.push_back(assess(results[k], checks_for(method, scenes[k].centres, spec.max_energy_error)));
  std::vector<std::optional<ErrorEstimate>> by_coarse(rows.size());
  std::vector<ErrorEstimate> coarse_cost(rows.size());
  std::vector<std::optional<double>> coarse_side(rows.size());
  if (spec.estimate_error) by_coarse = coarse_estimates(method, how, members, scenes, results, health, coarse_cost, coarse_side);
  bool fine = false;
  for (std::size_t k = 0; k < rows.size(); ++k) fine = fine || (estimable(health[k].outcome) && !by_coarse[k]);
  std::vector<RunResult> companions, second;
  if (spec.estimate_error && fine) companions = batch::run(method, members, detail::fixed_companion(how));
  // As integrate(): a second companion batch confirms the flagged lanes' estimates, bounds a run of a few steps and
  // checks the fine pairs the coarse side disagrees with (checks_fine_pair; the rounding draws only raise the
  // estimate it is compared with, so a lane that asks after them asks before).
  std::vector<ErrorEstimate> by_fine(rows.size());
  bool any_second = false;
  for (std::size_t k = 0; spec.estimate_error && k < rows.size(); ++k) {
    if (by_coarse[k] || !estimable(health[k].outcome)) continue;
    by_fine[k] =
        detail::fixed_step_estimate(method, scenes[k].bodies.front(), scenes[k].centres, results[k].final, companions[k].final);
    any_second = any_second || health[k].outcome == Outcome::unresolved || how.steps < detail::kFewSteps ||
                 detail::checks_fine_pair(method, scenes[k].centres, results[k], coarse_side[k], by_fine[k].value);
  }
  if (any_second) second = batch::run(method, members, detail::fixed_companion(how, 2));
  for (std::size_t k = 0; k < rows.size(); ++k) {
    SweepRow& row = rows[k];
    Health& h = health[k];
    row.result = std::move(results[k]);
    row.outcome = h.outcome;
    row.reason = std::move(h.why);
    if (!spec.estimate_error) {
      row.error.basis = "not asked for (estimate_error off)";
    } else if (by_coarse[k]) {
      row.error = std::move(*by_coarse[k]);
    } else if (estimable(row.outcome)) {
      row.error = std::move(by_fine[k]);
      row.error.force_evals = coarse_cost[k].force_evals + companions[k].force_evals;
      row.error.wall_s = coarse_cost[k].wall_s + companions[k].wall_s;
      if (row.outcome == Outcome::unresolved) {
        row.error.force_evals += second[k].force_evals;
        row.error.wall_s += second[k].wall_s;
        detail::confirm(row.error, method, scenes[k].bodies.front(), row.result.final, companions[k].final, second[k].final);
      }
    } else {
      row.error.basis = "the run ended " + std::string(outcome_name(row.outcome));
    }
  }
  confirm_deeper_lanes(rows, spec, method, members, how, by_coarse, companions, second);
  settle_lanes(rows, spec, method, members, scenes, how, by_coarse, coarse_side, companions, second);
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
/// rest kept), run to its departure by auto (twice_as_far_tol).
long add_row_start_distance(Encounter& e, const SweepSpec& spec, const std::vector<double>& point, const Body& body,
                            const BodyResult& near) {
  std::function<Expected<Scene>()> far;
  std::optional<PointData> d;  // the point's data, solved once for the far scene and the limit's rule
  if (spec.scene_text.empty()) {
    d = point_data(spec, point);
    far = [&] { return thesis_scene_twice_as_far(d->params, d->b, d->v_inf, d->arrival); };
  }
  Options o;
  o.track_invariants = false;
  o.cancel = spec.cancel;
  return add_start_distance(e, body, far, spec.accuracy, near.error.for_orbit(), "a scene file's body has no thesis start distance to double", o,
                            d && answers_at_limit(d->b, d->v_inf), &near);
}

/// The row of a run with its encounter (SweepSpec::scattering): integrate_encounter_checked (far legs where
/// auto runs it) with the encounter's events (encounter_options: it stops at the departure, the sweep's end
/// the latest), measured by measure_encounter; an encounter that did not finish by the end is the row's
/// outcome (incomplete).
SweepRow encounter_row(SweepRow row, const MethodInfo* method, const Scene& scene, const Advance& how,
                       const SweepSpec& spec) {
  const Body& body = scene.bodies.front();
  const Options options = encounter_options(body, scene.centres, sweep_options(spec), true);
  BodyResult r = detail::integrate_encounter_checked(body, scene.centres, method, how, options);  // checked by validate_sweep
  if (!ran(r.outcome)) return result_row(std::move(row), std::move(r));
  Encounter e = measure_encounter(body, scene.centres, r.run, r.events, options.events);
  if (e.outcome == Outcome::ok && r.outcome == Outcome::ok)
    row.start_distance_force_evals = add_row_start_distance(e, spec, row.point, body, r);
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
