// bodypoint: Kahan & Li's optimised symmetric compositions of the Strang step.
//
// W. Kahan, R.-C. Li, "Composition constants for raising the orders of unconventional schemes for
// ordinary differential equations", Math. Comp. 66 (1997) 1089-1099; the weights as tabulated in
// E. Hairer, C. Lubich, G. Wanner, Geometric Numerical Integration, 2nd ed. (2006), sec. V.3.2,
// eq. (3.11) (p6 s9) and (3.12) (p8 s17). Outermost weight first; the middle weight is derived
// from sum g = 1 (tests/lib/test_tables.cpp checks it against the published middle weight).
#pragma once

#include "bodypoint/splitting/composition.hpp"

namespace bodypoint::splitting {

/// Order 6, 9 stages (p6 s9); published middle weight 0.79854399093482996.
inline constexpr auto kahan_li6_weights = palindrome(std::array<double, 4>{
    0.39216144400731413928,
    0.33259913678935943860,
    -0.70624617255763935981,
    0.082213596293550800230});
inline constexpr double kahan_li6_middle = 0.79854399093482996340;
inline constexpr auto kahan_li6 = strang_dkd(kahan_li6_weights);

/// Order 8, 17 stages (p8 s17); published middle weight -0.60550853383003451170.
inline constexpr auto kahan_li8_weights = palindrome(std::array<double, 8>{
    0.13020248308889008088,
    0.56116298177510838456,
    -0.38947496264484728641,
    0.15884190655515560090,
    -0.39590389413323757734,
    0.18453964097831570709,
    0.25837438768632204729,
    0.29501172360931029887});
inline constexpr double kahan_li8_middle = -0.60550853383003451170;
inline constexpr auto kahan_li8 = strang_dkd(kahan_li8_weights);

// The table types (catalogue.hpp).
struct KahanLi6 {
  static constexpr std::string_view tag = "kl6", title = "Kahan-Li p6 s9",
                                    citation = "Kahan-Li 1997; HLW (3.11)";
  static constexpr int order = 6, stages = 9;
  static constexpr const auto& table = kahan_li6;
};
struct KahanLi8 {
  static constexpr std::string_view tag = "kl8", title = "Kahan-Li p8 s17",
                                    citation = "Kahan-Li 1997; HLW (3.12)";
  static constexpr int order = 8, stages = 17;
  static constexpr const auto& table = kahan_li8;
};

}  // namespace bodypoint::splitting
