// bodypoint: named scenes used by the work-precision driver, the benchmarks and the tests.
//
//   thesis       table 3.1 of the thesis, t_end = 50
//   close        the close encounter of issue #4: Kz = 0.1, d = 0.05, t_end = 80 (closest approach
//                ~0.2, the body is thrown back)
//   material     table 3.1 with B = 0 (a material point), t_end = 50
//   long         table 3.1 run to t_end = 1e4
//   two-centres  table 3.1 plus a second repelling centre (A = -1) at (40, 6, 0), t_end = 60
//   three-centres  two-centres plus an attracting centre (A = 1.5) at (80, -8, 0): centres of both signs,
//                passed one after the other, t_end = 60
// and the two scenes on which orders are measured (tests/lib/test_convergence.cpp, `study --name orders`).
#pragma once

#include "bodypoint/io.hpp"
#include "bodypoint/model.hpp"

#include <string>
#include <vector>

namespace bodypoint {

struct NamedScene {
  std::string name;
  Scene scene;
  double t_end;
};

inline std::vector<std::string> named_scene_names() {
  return {"thesis", "close", "material", "long", "two-centres", "three-centres"};
}

inline NamedScene named_scene(const std::string& name) {
  SceneParams sp;  // table 3.1
  if (name == "thesis") return {name, thesis_scene(sp), 50.0};
  if (name == "close") {
    sp.start.Kz = 0.1;
    sp.start.d = 0.05;
    return {name, thesis_scene(sp), 80.0};
  }
  if (name == "material") {
    sp.B = 0.0;
    return {name, thesis_scene(sp), 50.0};
  }
  if (name == "long") return {name, thesis_scene(sp), 1e4};
  if (name == "two-centres") {
    Scene s = thesis_scene(sp);
    s.centres.push_back({Vec3(40.0, 6.0, 0.0), -1.0});
    return {name, s, 60.0};
  }
  if (name == "three-centres") {
    Scene s = thesis_scene(sp);
    s.centres.push_back({Vec3(40.0, 6.0, 0.0), -1.0});
    s.centres.push_back({Vec3(80.0, -8.0, 0.0), 1.5});
    return {name, s, 60.0};
  }
  throw Error(unknown_name("scene", name, named_scene_names()));
}

/// The encounter used for convergence: table 3.1 moved close (L = 20, d = 1), stopped at t = 3,
/// next to the closest approach (~1 from the centre). Stopping inside the encounter matters: on a
/// complete scattering run the start and end states are force-free, and a method conjugate to a
/// higher-order one (Ruth 3 is, to order 4) shows that higher "effective" order instead.
inline NamedScene convergence_encounter(double B) {
  SceneParams sp;
  sp.B = B;
  sp.start.L = 20;
  sp.start.d = 1;
  return {"encounter", thesis_scene(sp), 3.0};
}

/// A bound, eccentric orbit about an attracting centre (A = 1, e ~ 0.44, period ~ 15), run for two
/// periods: truncation error grows with t while round-off grows only like sqrt(n), which widens the
/// asymptotic window of the high-order methods.
inline NamedScene convergence_orbit(double B) {
  Scene s;
  s.centres.push_back({Vec3::Zero(), 1.0});
  const BodyPoint p{1.0, B, 1.0};
  // K1 = (0, 1.2, 0), K2 = (0.3, 0, 0.5) give the spin a component off the orbit normal.
  const Momenta q{Vec3(1, 0, 0), Vec3(0, 1.2, 0), Vec3(0.3, 0, 0.5)};
  s.bodies.push_back({p, to_state(p, q), "orbit"});
  return {"orbit", s, 30.0};
}

}  // namespace bodypoint
