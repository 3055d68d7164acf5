// bodypoint: scene files (TOML, read with toml++).
//
//   [[centre]]                 one table per Coulomb centre
//   position = [x, y, z]       default [0, 0, 0]
//   A = -2.0                   required
//   law = "coulomb"            optional: coulomb (default), thesis-code, thesis-code-force (model.hpp)
//
//   [[body]]                   one table per (independent) body-point
//   name = "a"                 optional label
//   m = 1.0, B = 0.7, J = 1.0  required
//   either  R = [..], v = [..], w = [..]            (physical initial state)
//   or      d, L, K1, Kx, Kz (and optionally phase)   (the thesis's eq. 1.11-1.13)
//
// Unknown keys (named with the valid ones and a "did you mean"), wrong types and incomplete bodies
// are errors, as is a file that is not TOML. The Python module's Scene takes the same keys.
#pragma once

#include "bodypoint/model.hpp"

#include <string>

namespace bodypoint {

/// Reads and validates a scene; throws Error with "<file>: <what>" on any problem.
Scene read_scene_file(const std::string& path);

/// Parses scene text (`origin` names it in messages).
Scene parse_scene(const std::string& text, const std::string& origin);

}  // namespace bodypoint
