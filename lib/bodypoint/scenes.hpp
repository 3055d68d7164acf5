// bodypoint: named scenes used by the work-precision driver, the benchmarks and the tests.
//
//   thesis       table 3.1 of the thesis, t_end = 50
//   close        the close encounter of issue #4: Kz = 0.1, d = 0.05, t_end = 80 (closest approach
//                ~0.2, the body is thrown back)
//   material     table 3.1 with B = 0 (a material point), t_end = 50
//   long         table 3.1 run to t_end = 1e4
//   two-centres  table 3.1 plus a second repelling centre (A = -1) at (40, 6, 0), t_end = 60
#pragma once

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
  return {"thesis", "close", "material", "long", "two-centres"};
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
    validate(s);
    return {name, s, 60.0};
  }
  throw Error("unknown scene '" + name + "' (thesis, close, material, long, two-centres)");
}

}  // namespace bodypoint
