// bodypoint: Suzuki's fourth-order fractal composition.
//
// M. Suzuki, "Fractal decomposition of exponential operators with applications to many-body theories
// and Monte Carlo simulations", Phys. Lett. A 146 (1990) 319-323:
//   S_4(h) = S_2(p h) S_2(p h) S_2((1 - 4 p) h) S_2(p h) S_2(p h),  p = 1/(4 - 4^{1/3}),
// order 4, 5 stages. Its weights are smaller than the triple jump's (|1 - 4 p| = 0.66 against
// |x0| = 1.70), so it trades two more force evaluations per step for a smaller error constant
// (Hairer, Lubich & Wanner, Geometric Numerical Integration, 2nd ed., sec. II.4).
#pragma once

#include "bodypoint/splitting/composition.hpp"

#include <array>
#include <string_view>

namespace bodypoint::splitting {

inline constexpr double suzuki4_p = 1.0 / (4.0 - nth_root(4.0, 3));
inline constexpr std::array<double, 5> suzuki4_weights{suzuki4_p, suzuki4_p, 1.0 - 4.0 * suzuki4_p, suzuki4_p,
                                                       suzuki4_p};
inline constexpr auto suzuki4 = strang_dkd(suzuki4_weights);

// The table type (catalogue.hpp).
struct Suzuki4 {
  static constexpr std::string_view tag = "s4", title = "Suzuki fractal 4",
                                    citation = "Suzuki 1990";
  static constexpr int order = 4, stages = 5;
  static constexpr const auto& table = suzuki4;
};

}  // namespace bodypoint::splitting
