// bodypoint: the splitting tables flattened to their sub-flow sequences, one name per table, for the
// fixed-step methods (run.cpp), the time-transformed ones (adaptive/run.cpp) and the batch kernels
// (batch.hpp). verlet_ops is kick-drift-kick, strang_ops drift-kick-drift. Static storage, so that
// they can be template arguments of the composition engine.
#pragma once

#include "bodypoint/splitting/blanes_moan.hpp"
#include "bodypoint/splitting/classic.hpp"
#include "bodypoint/splitting/composition.hpp"
#include "bodypoint/splitting/kahan_li.hpp"
#include "bodypoint/splitting/mclachlan.hpp"
#include "bodypoint/splitting/sofroniou_spaletta.hpp"
#include "bodypoint/splitting/yoshida.hpp"

namespace bodypoint::splitting::ops {

inline constexpr auto euler_ops = flatten(euler);
inline constexpr auto verlet_ops = flatten(verlet_kdk);
inline constexpr auto strang_ops = flatten(strang_dkd_table);
inline constexpr auto ruth3_ops = flatten(ruth3);
inline constexpr auto y4_ops = flatten(yoshida4);
inline constexpr auto bm4_ops = flatten(blanes_moan4);
inline constexpr auto rkn4_ops = flatten(blanes_moan_rkn4);
inline constexpr auto rkn6_ops = flatten(blanes_moan_rkn6);
inline constexpr auto y6_ops = flatten(yoshida6);
inline constexpr auto kl6_ops = flatten(kahan_li6);
inline constexpr auto y8_ops = flatten(yoshida8);
inline constexpr auto y8d_ops = flatten(yoshida8d);
inline constexpr auto mcl8_ops = flatten(mclachlan8);
inline constexpr auto kl8_ops = flatten(kahan_li8);
inline constexpr auto ss10_ops = flatten(sofroniou_spaletta10);

}  // namespace bodypoint::splitting::ops
