// bodypoint: McLachlan's optimised eighth-order symmetric composition.
//
// R. I. McLachlan, "On the numerical integration of ordinary differential equations by symmetric
// composition methods", SIAM J. Sci. Comput. 16 (1995) 151-168; order 8, 15 stages (p8 s15 in
// Hairer, Lubich & Wanner, Geometric Numerical Integration, 2nd ed., sec. V.3.2, eq. (3.12)).
// Outermost weight first; the middle weight is derived from sum g = 1.
#pragma once

#include "bodypoint/splitting/composition.hpp"

namespace bodypoint::splitting {

/// Published middle weight -0.79688793935291635402.
inline constexpr auto mclachlan8_weights = palindrome(std::array<double, 7>{
    0.74167036435061295345,
    -0.40910082580003159400,
    0.19075471029623837995,
    -0.57386247111608226666,
    0.29906418130365592384,
    0.33462491824529818378,
    0.31529309239676659663});
inline constexpr double mclachlan8_middle = -0.79688793935291635402;
inline constexpr auto mclachlan8 = strang_dkd(mclachlan8_weights);

// The table type (catalogue.hpp).
struct McLachlan8 {
  static constexpr std::string_view tag = "mcl8", title = "McLachlan p8 s15",
                                    citation = "McLachlan 1995";
  static constexpr int order = 8, stages = 15;
  static constexpr const auto& table = mclachlan8;
};

}  // namespace bodypoint::splitting
