// bodypoint: Omelyan, Mryglod and Folk's optimised fourth-order splitting (PEFRL).
//
// I. P. Omelyan, I. M. Mryglod, R. Folk, "Optimized Forest-Ruth- and Suzuki-like algorithms for
// integration of motion in many-body systems", Comput. Phys. Commun. 146 (2002) 188-202, eq. 20 (the
// position-extended Forest-Ruth-like algorithm):
//   D(xi) K((1 - 2 lambda)/2) D(chi) K(lambda) D(1 - 2 (chi + xi)) K(lambda) D(chi) K((1 - 2 lambda)/2) D(xi)
// with xi = 0.1786178958448091, lambda = -0.2123418310626054, chi = -0.06626458266981849: order 4,
// 4 force evaluations per step, symmetric and drift-first. Its free parameters minimise the leading
// error term; the authors report an error about 100 times smaller than Forest-Ruth's at equal cost.
#pragma once

#include "bodypoint/splitting/composition.hpp"

#include <string_view>

namespace bodypoint::splitting {

inline constexpr double pefrl_xi = 0.1786178958448091;
inline constexpr double pefrl_lambda = -0.2123418310626054;
inline constexpr double pefrl_chi = -0.06626458266981849;
inline constexpr Table<5> pefrl{
    {pefrl_xi, pefrl_chi, 1.0 - 2.0 * (pefrl_chi + pefrl_xi), pefrl_chi, pefrl_xi},
    {(1.0 - 2.0 * pefrl_lambda) / 2.0, pefrl_lambda, pefrl_lambda, (1.0 - 2.0 * pefrl_lambda) / 2.0, 0.0}};

// The table type (catalogue.hpp).
struct Pefrl4 {
  static constexpr std::string_view tag = "pefrl", title = "Omelyan-Mryglod-Folk PEFRL",
                                    citation = "Omelyan-Mryglod-Folk 2002";
  static constexpr int order = 4, stages = 4;
  static constexpr const auto& table = pefrl;
};

}  // namespace bodypoint::splitting
