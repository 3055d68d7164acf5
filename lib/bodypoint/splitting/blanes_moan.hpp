// bodypoint: Blanes & Moan's optimised fourth-order splitting.
//
// S. Blanes, P. C. Moan, "Practical symplectic partitioned Runge-Kutta and Runge-Kutta-Nystrom
// methods", J. Comput. Appl. Math. 142 (2002) 313-330, table 2, method S6: order 4, 6 stages,
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

}  // namespace bodypoint::splitting
