// bodypoint: what a run reports of its first integrals and its resolution (docs/physics.md "First
// integrals", "Resolution"), apart from the monitor that measures them (invariants.hpp), so that the
// run's interface (run.hpp) does not reach the force kernel.
#pragma once

#include <cmath>
#include <limits>

namespace bodypoint {

/// Maxima over a run of the thesis's metric |X_i - X_0|/|X_0| (absolute where X_0 = 0) and of
/// |K2Q_i - K2Q_0|. `has_K2Q` is false in fields where K2Q is not an integral.
struct InvariantStats {
  double max_rel_dE = 0.0;
  double max_rel_dK2sq = 0.0;
  double max_abs_dK2Q = 0.0;
  bool has_K2Q = false;
  /// Closest observed distance to an attracting centre, and the distance at the start (both infinite
  /// without an attracting centre): a fall onto a centre shows as min/start ~ 0.
  double min_r_attracting = std::numeric_limits<double>::infinity();
  double r0_attracting = std::numeric_limits<double>::infinity();
  /// Resolution (docs/physics.md "Resolution"): the largest angle the spin turned through about K1 in
  /// one step, Omega_so dt with Omega_so = |B| |K1|/D at the step's end, and the cosine of the largest
  /// angle through which the direction to a centre (A != 0) turned in one step (1: none turned).
  double max_spin_angle = 0.0;
  double min_turn_cos = 1.0;
};


}  // namespace bodypoint
