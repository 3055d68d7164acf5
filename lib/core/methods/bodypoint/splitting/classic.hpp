// bodypoint: low-order splitting tables (orders 1-3).
//
// Tables are D(a_i) K(b_i) pairs (composition.hpp). Used by both families: the thesis's
// frozen-gyroscopic kernel (thesis-*) and the exact Lie-Poisson kernel (lp-*).
#pragma once

#include "bodypoint/splitting/composition.hpp"

namespace bodypoint::splitting {

/// Symplectic (Lie-Trotter) Euler, order 1, 1 stage: D(h) K(h).
/// Thesis sec. 2.5 ("symplectic Euler", C_1 = D_1 = 1).
inline constexpr Table<1> euler{{1.0}, {1.0}};

/// Stormer-Verlet, kick-drift-kick, order 2, 1 force evaluation per step with FSAL:
/// K(h/2) D(h) K(h/2). Thesis sec. 2.5 ("Verlet", C = (0, 1), D = (1/2, 1/2)).
inline constexpr auto verlet_kdk = strang_kdk(std::array<double, 1>{1.0});

/// Strang/leapfrog, drift-kick-drift, order 2, 1 stage: D(h/2) K(h) D(h/2)
/// (Strang 1968, SIAM J. Numer. Anal. 5, 506).
inline constexpr auto strang_dkd_table = strang_dkd(std::array<double, 1>{1.0});

/// Ruth's third-order method, 3 stages, in the thesis's drift-first form (sec. 2.5):
/// C = (1, -2/3, 2/3), D = (-1/24, 3/4, 7/24); the adjoint of R. D. Ruth, IEEE Trans. Nucl. Sci.
/// 30 (1983) 2669, table with c = (7/24, 3/4, -1/24), d = (2/3, -2/3, 1).
inline constexpr Table<3> ruth3{{1.0, -2.0 / 3.0, 2.0 / 3.0}, {-1.0 / 24.0, 3.0 / 4.0, 7.0 / 24.0}};

// The table types (catalogue.hpp).
struct Euler {
  static constexpr std::string_view tag = "euler", title = "Lie-Trotter D K",
                                    citation = "thesis sec. 2.5";
  static constexpr int order = 1, stages = 1;
  static constexpr const auto& table = euler;
};
struct VerletKdk {
  static constexpr std::string_view tag = "verlet", title = "Strang, kick-drift-kick",
                                    citation = "thesis sec. 2.5";
  static constexpr int order = 2, stages = 1;
  static constexpr const auto& table = verlet_kdk;
};
struct StrangDkd {
  static constexpr std::string_view tag = "verlet-dkd", title = "Strang, drift-kick-drift",
                                    citation = "Strang 1968";
  static constexpr int order = 2, stages = 1;
  static constexpr const auto& table = strang_dkd_table;
};
struct Ruth3 {
  static constexpr std::string_view tag = "ruth3", title = "Ruth third order",
                                    citation = "Ruth 1983; thesis sec. 2.5";
  static constexpr int order = 3, stages = 3;
  static constexpr const auto& table = ruth3;
};

}  // namespace bodypoint::splitting
