// `bodypoint study --name stress`: one method of each family on hostile scenes. Every run
// ends as ok (finite, energy error below 1), refused (with the reason: a method that does not accept
// the scene, a budget, a validation), diverged or collision (flagged by assess()). Nothing is
// reported as a number that does not mean one.
#include "stress.hpp"

#include "bodypoint/bodypoint.hpp"
#include "checked.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/detail/model_parts.hpp"
#include "bodypoint/methods.hpp"
#include "budget.hpp"
#include "bodypoint/detail/run_parts.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <utility>

namespace bodypoint::cli {
namespace {

/// Per-run budget of the study: a run estimated above it is refused with the estimate (--quick: 2 s,
/// so that the whole quick study takes well under a minute).
constexpr double kStressMaxSeconds = 120.0;
constexpr double kQuickStressMaxSeconds = 2.0;

struct StressCase {
  std::string name;
  Scene scene;
  double t_end;
  double h;             ///< fixed step (and ds of the time-transformed methods, which run to t_end)
  std::string invalid;  ///< why the case has no valid scene ("" when it has): every method refuses it
};

/// A bound orbit: A = +1, R = (1,0,0), K1 = (0,0.8,0), K2 = (0,0.3,0.2), E0 = -0.5745.
Scene bound_orbit() {
  Scene s;
  s.centres.push_back({Vec3::Zero(), 1.0});
  const BodyPoint p{1.0, 0.7, 1.0};
  s.bodies.push_back({p, to_state(p, Momenta{Vec3(1, 0, 0), Vec3(0, 0.8, 0), Vec3(0, 0.3, 0.2)}), "orbit"});
  return s;
}

std::vector<StressCase> cases(bool quick) {
  std::vector<StressCase> out;
  auto add = [&](std::string name, const std::function<Expected<Scene>()>& make, double t_end, double h) {
    // Each case's scene is checked here, once (valid_scene): the runs of every method take it as checked.
    const Expected<Scene> scene = make();
    if (scene) out.push_back({std::move(name), *scene, t_end, h, ""});
    else out.push_back({name + " [invalid: " + scene.error() + "]", Scene{}, t_end, h, scene.error()});
  };
  add("bound orbit, " + std::string(quick ? "1e6" : "1e8") + " steps", [] { return valid_scene(bound_orbit()); },
      quick ? 1e4 : 1e6, 0.01);
  for (const double A : {-2.0, 2.0}) {
    add("head-on A=" + fmt(A) + " (d/L = 1e-4)", [A] {
      SceneParams p;
      p.A = A;
      p.start.d = 0.02;
      p.start.Kz = 0.1;
      return valid_thesis_scene(p);
    }, 80.0, 1e-3);
  }
  add("head-on A=2, material point (B=0)", [] {
    SceneParams p;
    p.A = 2.0;
    p.B = 0.0;
    p.start.d = 0.02;
    p.start.Kz = 0.1;
    return valid_thesis_scene(p);
  }, 80.0, 1e-3);
  for (const double D : {1.0, 1e-3, 1e-6, 1e-9, 1e-12}) {
    add("D=" + fmt(D), [D] {
      SceneParams p;
      p.m = 1.0;
      p.J = 1.0;
      p.B = std::sqrt(1.0 - D);
      return valid_thesis_scene(p);
    }, 50.0, 1e-3);
  }
  for (const double K1 : {1e-8, 1e-4, 1.0, 1e4, 1e8}) {
    add("|K1|=" + fmt(K1), [K1] {
      SceneParams p;
      p.start.K1 = K1;
      return valid_thesis_scene(p);
    }, 50.0, 1e-3);
  }
  for (const double L : {1e3, 1e6, 1e9, 1e12}) {
    add("L=" + fmt(L), [L] {
      SceneParams p;
      p.start.L = L;
      return valid_thesis_scene(p);
    }, 50.0, 1e-3);
  }
  return out;
}

/// One method of each family and of each scene check within it (logH and TTL assume different
/// scenes), from the catalogue: the family's first method of order 4, or its first method where it has
/// none of order 4 (the step-size-controlled peers, ks).
std::vector<const MethodInfo*> stress_methods() {
  std::vector<const MethodInfo*> chosen;
  const auto same_kind = [](const MethodInfo* a, const MethodInfo& b) { return a->family == b.family && a->check == b.check; };
  for (const MethodInfo& m : methods()) {
    const auto kind = std::find_if(chosen.begin(), chosen.end(), [&](const MethodInfo* c) { return same_kind(c, m); });
    if (kind == chosen.end()) chosen.push_back(&m);
    else if ((*kind)->order != 4 && m.order == 4) *kind = &m;
  }
  return chosen;
}

StressRow run_case(const StressCase& c, const MethodInfo& m, double max_seconds) {
  StressRow row;
  row.case_name = c.name;
  row.method = std::string(m.name);
  if (!c.invalid.empty()) {
    row.outcome = Outcome::refused;
    row.reason = "invalid: " + c.invalid;
    return row;
  }
  const Body& body = c.scene.bodies.front();
  // ds: one fictitious step covers ~10 fixed steps far from a centre
  const double step = c.h * (is_time_transformed(m) ? 10.0 : 1.0);
  const Advance how = advance_of(m, {.step = step, .end = c.t_end, .grid = FixedGrid::nearest});
  const Options options;
  // The scene was checked (cases); the step, its end and the options are the study's own.
  if (const auto e = estimate_work(m, body, c.scene.centres, how, options)) {
    if (std::string why = over_budget(*e, max_seconds); !why.empty()) {
      row.outcome = Outcome::refused;
      row.reason = std::move(why);
      return row;
    }
  }
  BodyResult r = detail::integrate_checked(body, c.scene.centres, &m, how, options);
  row.outcome = r.outcome;
  row.reason = std::move(r.reason);
  if (ran(r.outcome)) {
    row.max_rel_dE = r.run.invariants ? r.run.invariants->max_rel_dE : std::nan("");
    row.err_estimate = r.error.value;
    row.steps = r.run.steps;
    row.wall_s = r.run.wall_s;
  }
  return row;
}

}  // namespace

std::vector<StressRow> run_stress(bool quick, const std::function<void(const StressRow&)>& each) {
  std::vector<StressRow> rows;
  for (const StressCase& c : cases(quick))
    for (const MethodInfo* m : stress_methods()) {
      rows.push_back(run_case(c, *m, quick ? kQuickStressMaxSeconds : kStressMaxSeconds));
      if (each) each(rows.back());
    }
  return rows;
}

void write_stress(std::ostream& csv, std::ostream& md, const std::vector<StressRow>& rows) {
  csv << "case,method,outcome,max_rel_dE,steps,wall_s,reason,err_estimate\n"
      << "# bodypoint study stress, revision " << git_revision() << "\n"
      << "# outcome: ok | refused (not run, reason) | failed (started and stopped, reason) | diverged | unresolved | inaccurate | collision (flagged, reason; "
         "docs/physics.md, Resolution and accuracy flags); max_rel_dE only for runs; err_estimate = the run's estimated "
         "relative error (a companion run at up to twice or half the step; docs/physics.md, Error estimate of a run by step; NaN: none)\n";
  for (const StressRow& r : rows) {
    csv << CsvLine().quoted(r.case_name).text(r.method).text(std::string(outcome_name(r.outcome))).num(r.max_rel_dE).count(r.steps)
               .num(r.wall_s).quoted(r.reason).num(r.err_estimate).str()
        << '\n';
  }
  md << "| case | method | outcome | max rel dE | steps | wall [s] |\n|---|---|---|---|---|---|\n";
  for (const StressRow& r : rows) {
    std::ostringstream e, w;
    e << std::setprecision(2) << std::scientific << r.max_rel_dE;
    w << std::setprecision(3) << r.wall_s;
    std::string outcome(outcome_name(r.outcome));
    if (!r.reason.empty()) outcome += ": " + r.reason.substr(0, 110) + (r.reason.size() > 110 ? "..." : "");
    std::replace(outcome.begin(), outcome.end(), '|', '/');
    md << "| " << r.case_name << " | " << r.method << " | " << outcome << " | "
       << (r.outcome == Outcome::refused ? "-" : e.str()) << " | " << (r.outcome == Outcome::refused ? "-" : std::to_string(r.steps))
       << " | " << (r.outcome == Outcome::refused ? "-" : w.str()) << " |\n";
  }
}

}  // namespace bodypoint::cli
