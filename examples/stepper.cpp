// A stepper loop: one body advanced to t = 1, 2, ..., 10 with the time-transformed logH method
// (fictitious step ds = 0.01), printing its distance from the centre and its energy error after
// each segment; each segment continues from where the previous one ended.
#include <bodypoint/bodypoint.hpp>
#include <bodypoint/invariants.hpp>

#include <cmath>
#include <cstdio>

int main() {
  bodypoint::SceneParams p;
  p.start.L = 20.0;  // start closer than table 3.1, so that the encounter happens by t = 10
  const bodypoint::Scene scene = bodypoint::thesis_scene(p);
  const bodypoint::Body& body = scene.bodies.front();
  const double E0 = bodypoint::energy(body.p, scene.centres, body.s0);

  bodypoint::Stepper stepper("logh-kl6", body, scene.centres, 0.01);
  for (int k = 1; k <= 10; ++k) {
    if (stepper.advance_to(k) != bodypoint::Outcome::ok) {
      std::fprintf(stderr, "stepper: %s\n", stepper.reason().c_str());
      return 1;
    }
    const bodypoint::State& s = stepper.state();
    const double E = bodypoint::energy(body.p, scene.centres, s);
    std::printf("t %g r %.12g rel_dE %.2e\n", stepper.time(), s.R.norm(), std::abs(E - E0) / std::abs(E0));
  }
  std::printf("force_evals %ld\n", stepper.force_evals());
  return 0;
}
