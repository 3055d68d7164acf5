// bodypoint: Blanes & Moan's optimised splittings.
//
// S. Blanes, P. C. Moan, "Practical symplectic partitioned Runge-Kutta and Runge-Kutta-Nystrom
// methods", J. Comput. Appl. Math. 142 (2002) 313-330.
//
// Table 2, method S6 (general splitting): order 4, 6 stages,
//   D(a1) K(b1) D(a2) K(b2) D(a3) K(b3) D(a4) K(b3) D(a3) K(b2) D(a2) K(b1) D(a1),
// a4 = 1 - 2 (a1 + a2 + a3), b3 = 1/2 - (b1 + b2). For a general splitting the order conditions are
// symmetric in the two parts; the drift takes the a's so that 7 drifts merge to 6 per step.
#pragma once

#include "bodypoint/splitting/composition.hpp"

namespace bodypoint::splitting {

namespace detail {
inline constexpr double bm_a1 = 0.0792036964311957;
inline constexpr double bm_a2 = 0.353172906049774;
inline constexpr double bm_a3 = -0.0420650803577195;
inline constexpr double bm_a4 = 1.0 - 2.0 * (bm_a1 + bm_a2 + bm_a3);
inline constexpr double bm_b1 = 0.209515106613362;
inline constexpr double bm_b2 = -0.143851773179818;
inline constexpr double bm_b3 = 0.5 - (bm_b1 + bm_b2);
}  // namespace detail

inline constexpr Table<7> blanes_moan4{
    {detail::bm_a1, detail::bm_a2, detail::bm_a3, detail::bm_a4, detail::bm_a3, detail::bm_a2,
     detail::bm_a1},
    {detail::bm_b1, detail::bm_b2, detail::bm_b3, detail::bm_b3, detail::bm_b2, detail::bm_b1, 0.0}};

/// Table 3, methods SRKN_6^b (order 4, 6 force evaluations) and SRKN_11^b (order 6, 11), kick first:
///   K(b1) D(a1) K(b2) D(a2) ... D(a2) K(b2) D(a1) K(b1),  the middle coefficient of each kind derived
///   from consistency. They assume the Runge-Kutta-Nystrom condition {V,{V,{V,T}}} = 0, which holds
///   for the body-point although T is not T(p) alone: {V,T} = -F.dT/dK1 = -F.(J K1 - B K2)/D is linear
///   in (K1, K2) with R-dependent coefficients, {V,{V,T}} = F.F J/D depends on R only, and its bracket
///   with V(R) vanishes (both are functions of R, and {R_i, R_j} = 0).
namespace detail {
inline constexpr double rkn4_b1 = 0.0829844064174052;
inline constexpr double rkn4_b2 = 0.396309801498368;
inline constexpr double rkn4_b3 = -0.0390563049223486;
inline constexpr double rkn4_b4 = 1.0 - 2.0 * (rkn4_b1 + rkn4_b2 + rkn4_b3);
inline constexpr double rkn4_a1 = 0.245298957184271;
inline constexpr double rkn4_a2 = 0.604872665711080;
inline constexpr double rkn4_a3 = 0.5 - (rkn4_a1 + rkn4_a2);

inline constexpr double rkn6_b[6] = {0.0414649985182624, 0.198128671918067, -0.0400061921041533,
                                     0.0752539843015807, -0.0115113874206879,
                                     0.5 - (0.0414649985182624 + 0.198128671918067 - 0.0400061921041533 +
                                            0.0752539843015807 - 0.0115113874206879)};
inline constexpr double rkn6_a[6] = {0.123229775946271, 0.290553797799558, -0.127049212625417,
                                     -0.246331761062075, 0.357208872795928,
                                     1.0 - 2.0 * (0.123229775946271 + 0.290553797799558 - 0.127049212625417 -
                                                  0.246331761062075 + 0.357208872795928)};
}  // namespace detail

inline constexpr Table<7> blanes_moan_rkn4{
    {0.0, detail::rkn4_a1, detail::rkn4_a2, detail::rkn4_a3, detail::rkn4_a3, detail::rkn4_a2, detail::rkn4_a1},
    {detail::rkn4_b1, detail::rkn4_b2, detail::rkn4_b3, detail::rkn4_b4, detail::rkn4_b3, detail::rkn4_b2,
     detail::rkn4_b1}};

inline constexpr Table<12> blanes_moan_rkn6 = [] {
  Table<12> t{};
  // a: 0, a1..a5, a6 (middle), a5..a1; b: b1..b6, b6..b1.
  t.a[0] = 0.0;
  for (int i = 0; i < 6; ++i) t.a[1 + i] = detail::rkn6_a[i];
  for (int i = 0; i < 5; ++i) t.a[7 + i] = detail::rkn6_a[4 - i];
  for (int i = 0; i < 6; ++i) {
    t.b[i] = detail::rkn6_b[i];
    t.b[11 - i] = detail::rkn6_b[i];
  }
  return t;
}();

// The table types (catalogue.hpp).
struct BlanesMoan4 {
  static constexpr std::string_view tag = "bm4", title = "Blanes-Moan S6",
                                    citation = "Blanes-Moan 2002, table 2";
  static constexpr int order = 4, stages = 6;
  static constexpr const auto& table = blanes_moan4;
};
struct BlanesMoanRkn4 {
  static constexpr std::string_view tag = "rkn4", title = "Blanes-Moan SRKN_6^b (RKN)",
                                    citation = "Blanes-Moan 2002, table 3";
  static constexpr int order = 4, stages = 6;
  static constexpr bool nystrom = true;
  static constexpr const auto& table = blanes_moan_rkn4;
};
struct BlanesMoanRkn6 {
  static constexpr std::string_view tag = "rkn6", title = "Blanes-Moan SRKN_11^b (RKN)",
                                    citation = "Blanes-Moan 2002, table 3";
  static constexpr int order = 6, stages = 11;
  static constexpr bool nystrom = true;
  static constexpr const auto& table = blanes_moan_rkn6;
};

}  // namespace bodypoint::splitting
