// `bodypoint study --name stress`: one method of each family on hostile scenes (issue #12). Every run
// ends as ok (finite, energy error below 1), refused (with the reason: a method that does not accept
// the scene, a budget, a validation), diverged or collision (flagged by assess()). Nothing is
// reported as a number that does not mean one.
#include "stress.hpp"

#include "bodypoint/io.hpp"
#include "bodypoint/methods.hpp"
#include "budget.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

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
  double h;  ///< fixed step (and ds of the time-transformed methods, which run to t_end)
};

Scene thesis(SceneParams p) { return thesis_scene(p); }

/// The bound orbit of issue #12: A = +1, R = (1,0,0), K1 = (0,0.8,0), K2 = (0,0.3,0.2), E0 = -0.5745.
Scene bound_orbit() {
  Scene s;
  s.centres.push_back({Vec3::Zero(), 1.0});
  const BodyPoint p{1.0, 0.7, 1.0};
  s.bodies.push_back({p, to_state(p, Momenta{Vec3(1, 0, 0), Vec3(0, 0.8, 0), Vec3(0, 0.3, 0.2)}), "orbit"});
  return s;
}

std::vector<StressCase> cases(bool quick) {
  std::vector<StressCase> out;
  auto add = [&](std::string name, const std::function<Scene()>& make, double t_end, double h) {
    try {
      out.push_back({std::move(name), make(), t_end, h});
    } catch (const Error& e) {
      out.push_back({name + " [invalid: " + e.what() + "]", Scene{}, t_end, h});
    }
  };
  add("bound orbit, " + std::string(quick ? "1e6" : "1e8") + " steps", bound_orbit, quick ? 1e4 : 1e6, 0.01);
  for (const double A : {-2.0, 2.0}) {
    add("head-on A=" + fmt(A) + " (d/L = 1e-4)", [A] {
      SceneParams p;
      p.A = A;
      p.start.d = 0.02;
      p.start.Kz = 0.1;
      return thesis(p);
    }, 80.0, 1e-3);
  }
  add("head-on A=2, material point (B=0)", [] {
    SceneParams p;
    p.A = 2.0;
    p.B = 0.0;
    p.start.d = 0.02;
    p.start.Kz = 0.1;
    return thesis(p);
  }, 80.0, 1e-3);
  for (const double D : {1.0, 1e-3, 1e-6, 1e-9, 1e-12}) {
    add("D=" + fmt(D), [D] {
      SceneParams p;
      p.m = 1.0;
      p.J = 1.0;
      p.B = std::sqrt(1.0 - D);
      return thesis(p);
    }, 50.0, 1e-3);
  }
  for (const double K1 : {1e-8, 1e-4, 1.0, 1e4, 1e8}) {
    add("|K1|=" + fmt(K1), [K1] {
      SceneParams p;
      p.start.K1 = K1;
      return thesis(p);
    }, 50.0, 1e-3);
  }
  for (const double L : {1e3, 1e6, 1e9, 1e12}) {
    add("L=" + fmt(L), [L] {
      SceneParams p;
      p.start.L = L;
      return thesis(p);
    }, 50.0, 1e-3);
  }
  return out;
}

/// One method of each family: the thesis's, Odeint's fixed and controlled steppers, GSL's, the exact
/// splitting, the two time transformations and KS.
std::vector<std::string> stress_methods() {
  std::vector<std::string> m = {"thesis-verlet", "rk4", "odeint-dopri5", "lp-y4", "logh-y4", "ttl-y4", "ks"};
  if (find_method("gsl-rk8pd")) m.insert(m.begin() + 3, "gsl-rk8pd");
  return m;
}

StressRow run_case(const StressCase& c, const MethodInfo& m, double max_seconds) {
  StressRow row;
  row.case_name = c.name;
  row.method = std::string(m.name);
  if (c.scene.bodies.empty()) {
    row.status = "refused";
    row.reason = c.name.substr(c.name.find('[') + 1);
    row.reason.pop_back();
    return row;
  }
  try {
    const Body& body = c.scene.bodies.front();
    RunSpec spec;
    spec.track_invariants = true;
    spec.tol = 1e-10;
    if (is_step_controlled(m)) {
      spec.h = c.h;
      spec.steps = 1;
      spec.t_end = c.t_end;
    } else if (is_time_transformed(m)) {
      spec.h = c.h * 10;  // ds: one fictitious step covers ~10 fixed steps far from a centre
      spec.t_end = c.t_end;
      spec.steps = 0;
    } else {
      spec.h = c.h;
      spec.steps = static_cast<long>(std::llround(c.t_end / c.h));
    }
    if (const auto e = estimate_work(m, body, c.scene.centres, spec)) check_budget(*e, max_seconds, true);
    const RunResult r = run(m, body, c.scene.centres, spec);
    const Health h = assess(r, checks_for(m, c.scene.centres));
    row.status = h.status;
    row.reason = h.why;
    row.max_rel_dE = r.invariants ? r.invariants->max_rel_dE : std::nan("");
    row.steps = r.steps;
    row.wall_s = r.wall_s;
  } catch (const Error& e) {
    row.status = "refused";
    row.reason = e.what();
  }
  return row;
}

}  // namespace

std::vector<StressRow> run_stress(bool quick, const std::function<void(const StressRow&)>& each) {
  std::vector<StressRow> rows;
  for (const StressCase& c : cases(quick))
    for (const std::string& name : stress_methods()) {
      rows.push_back(run_case(c, method_or_throw(name), quick ? kQuickStressMaxSeconds : kStressMaxSeconds));
      if (each) each(rows.back());
    }
  return rows;
}

void write_stress(std::ostream& csv, std::ostream& md, const std::vector<StressRow>& rows) {
  csv << "case,method,status,max_rel_dE,steps,wall_s,reason\n"
      << "# bodypoint study stress, revision " << git_revision() << "\n"
      << "# status: ok | refused (not run, reason) | diverged | unresolved | inaccurate | collision (flagged, reason; "
         "docs/physics.md, Resolution and accuracy flags); max_rel_dE only for runs\n";
  for (const StressRow& r : rows) {
    csv << CsvLine().quoted(r.case_name).text(r.method).text(r.status).num(r.max_rel_dE).count(r.steps)
               .num(r.wall_s).quoted(r.reason).str()
        << '\n';
  }
  md << "| case | method | outcome | max rel dE | steps | wall [s] |\n|---|---|---|---|---|---|\n";
  for (const StressRow& r : rows) {
    std::ostringstream e, w;
    e << std::setprecision(2) << std::scientific << r.max_rel_dE;
    w << std::setprecision(3) << r.wall_s;
    std::string outcome = r.status;
    if (!r.reason.empty()) outcome += ": " + r.reason.substr(0, 110) + (r.reason.size() > 110 ? "..." : "");
    std::replace(outcome.begin(), outcome.end(), '|', '/');
    md << "| " << r.case_name << " | " << r.method << " | " << outcome << " | "
       << (r.status == "refused" ? "-" : e.str()) << " | " << (r.status == "refused" ? "-" : std::to_string(r.steps))
       << " | " << (r.status == "refused" ? "-" : w.str()) << " |\n";
  }
}

}  // namespace bodypoint::cli
