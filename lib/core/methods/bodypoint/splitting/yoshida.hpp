// bodypoint: Yoshida's symmetric compositions of the Strang step, orders 4, 6, 8.
//
// H. Yoshida, "Construction of higher order symplectic integrators", Phys. Lett. A 150 (1990)
// 262-268. The triple jump (eq. 5.2-5.4; thesis sec. 2.4 and appendix 2, eq. P2.1-P2.3)
//   S_{2k+2}(h) = S_{2k}(x1 h) S_{2k}(x0 h) S_{2k}(x1 h),  x1 = 1/(2 - 2^{1/(2k+1)}),  x0 = 1 - 2 x1,
// is evaluated at compile time, so every weight is exact to rounding.
#pragma once

#include "bodypoint/splitting/composition.hpp"

namespace bodypoint::splitting {

/// Order 4, 3 stages (Forest & Ruth 1990, Physica D 43, 105; Yoshida 1990 eq. 4.14; thesis
/// eq. 2.9-2.10): g = (x1, x0, x1).
inline constexpr auto yoshida4_weights = triple_jump(std::array<double, 1>{1.0}, 2);
inline constexpr auto yoshida4 = strang_dkd(yoshida4_weights);

/// Order 6, 9 stages: the triple jump of yoshida4, g = (y1 x1, y1 x0, y1 x1, y0 x1, y0 x0, y0 x1,
/// y1 x1, y1 x0, y1 x1). In DKD form this is exactly the thesis's table 2.1 (C_1..C_10, D_1..D_10).
inline constexpr auto yoshida6_weights = triple_jump(yoshida4_weights, 4);
inline constexpr auto yoshida6 = strang_dkd(yoshida6_weights);

/// Order 8, 27 stages: the triple jump of yoshida6 (thesis appendix 2 with n = 3).
inline constexpr auto yoshida8_weights = triple_jump(yoshida6_weights, 6);
inline constexpr auto yoshida8 = strang_dkd(yoshida8_weights);

/// Order 8, 15 stages: Yoshida 1990, table 2, solution D, listed outermost first
/// (w7, w6, ..., w1); the middle weight w0 = 1 - 2 (w1 + ... + w7) is derived. The paper prints
/// 15 significant digits, so the order conditions hold to about 1e-15.
inline constexpr auto yoshida8d_weights = palindrome(std::array<double, 7>{
    0.914844246229740,    // w7
    0.253693336566229,    // w6
    -1.44485223686048,    // w5
    -0.158240635368243,   // w4
    1.93813913762276,     // w3
    -1.96061023297549,    // w2
    0.102799849391985});  // w1
inline constexpr auto yoshida8d = strang_dkd(yoshida8d_weights);

// The table types (catalogue.hpp).
struct Yoshida4 {
  static constexpr std::string_view tag = "y4", title = "Yoshida/Forest-Ruth 4, triple jump",
                                    citation = "Yoshida 1990; Forest-Ruth 1990; thesis eq. 2.9-2.10";
  static constexpr int order = 4, stages = 3;
  static constexpr const auto& table = yoshida4;
};
struct Yoshida6 {
  static constexpr std::string_view tag = "y6", title = "Yoshida 6, triple jump",
                                    citation = "Yoshida 1990; thesis table 2.1";
  static constexpr int order = 6, stages = 9;
  static constexpr const auto& table = yoshida6;
};
struct Yoshida8 {
  static constexpr std::string_view tag = "y8", title = "Yoshida 8, triple jump",
                                    citation = "Yoshida 1990; thesis appendix 2";
  static constexpr int order = 8, stages = 27;
  static constexpr const auto& table = yoshida8;
};
struct Yoshida8D {
  static constexpr std::string_view tag = "y8d", title = "Yoshida 8, solution D",
                                    citation = "Yoshida 1990, table 2";
  static constexpr int order = 8, stages = 15;
  static constexpr const auto& table = yoshida8d;
};

}  // namespace bodypoint::splitting
