// One scene to a final state: the thesis's reference scene (table 3.1) integrated with the exact
// Lie-Poisson Yoshida-4 method, h = 1e-3 to t = 50; prints the final state and how well the first
// integrals were kept; then the whole result as one JSON line, the fields `bodypoint simulate --json`
// prints (record.hpp).
#include <bodypoint/bodypoint.hpp>
#include <bodypoint/record.hpp>

#include <cstdio>
#include <sstream>

int main() {
  const bodypoint::Scene scene = bodypoint::thesis_scene(bodypoint::SceneParams{});
  const bodypoint::Advance how = bodypoint::FixedSteps{1e-3, 50000};
  const bodypoint::Result r = bodypoint::integrate(scene, "lp-y4", how);
  if (r.outcome != bodypoint::Outcome::ok) {
    std::fprintf(stderr, "final_state: %s\n", r.reason.c_str());
    return 1;
  }
  const bodypoint::RunResult& run = r.bodies.front().run;
  const bodypoint::State& s = run.final;
  std::printf("t_end %.17g\n", run.t_end);
  std::printf("R %.17g %.17g %.17g\n", s.R.x(), s.R.y(), s.R.z());
  std::printf("v %.17g %.17g %.17g\n", s.v.x(), s.v.y(), s.v.z());
  std::printf("w %.17g %.17g %.17g\n", s.w.x(), s.w.y(), s.w.z());
  std::printf("max_rel_dE %.3g\nmax_abs_dK2Q %.3g\nforce_evals %ld\n", run.invariants->max_rel_dE,
              run.invariants->max_abs_dK2Q, run.force_evals);
  std::ostringstream json;
  bodypoint::write_json(json, bodypoint::body_record(r.bodies.front(), how, {}));
  std::printf("json %s\n", json.str().c_str());
  return 0;
}
