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
#include <vector>

namespace bodypoint {

/// Reads and validates a scene; throws Error with "<file>: <what>" on any problem.
Scene read_scene_file(const std::string& path);
/// A scene file's text, read as read_scene_file reads it (a regular file of at most 16 MB).
std::string read_scene_text(const std::string& path);

/// One number of a scene file set by its key path (a sweep's axis over a scene):
///   centreK.A, centreK.position.x|y|z        the K-th [[centre]] (from 1); `centre.` every centre
///   bodyK.KEY, NAME.KEY, body.KEY            the K-th [[body]], the body called NAME, every body:
///     KEY = m, B, J, one of the thesis's d, L, K1, Kx, Kz, phase (a body given so), or R|v|w.x|y|z
/// The file's own checks then apply to the changed scene (a body keeps one form).
struct SceneValue {
  std::string key;
  double value = 0.0;
};

/// Parses scene text (`origin` names it in messages), with `set` applied to the file's keys first;
/// Error naming the key for a key the scene does not have, or a value that is not a body's parameter.
/// The scene as a whole is checked once, where it is run (validate; read_scene_file checks it).
Scene parse_scene(const std::string& text, const std::string& origin, const std::vector<SceneValue>& set = {});

}  // namespace bodypoint
