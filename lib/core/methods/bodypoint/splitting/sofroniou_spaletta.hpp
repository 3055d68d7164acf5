// bodypoint: Sofroniou & Spaletta's tenth-order symmetric composition.
//
// M. Sofroniou, G. Spaletta, "Derivation of symmetric composition constants for symmetric
// integrators", Optim. Methods Softw. 20 (2005) 597-613; order 10, 35 stages.
// Outermost weight first; the middle weight is derived from sum g = 1.
#pragma once

#include "bodypoint/splitting/composition.hpp"

namespace bodypoint::splitting {

/// Published middle weight 0.04931773575959453792.
inline constexpr auto sofroniou_spaletta10_weights = palindrome(std::array<double, 17>{
    0.07879572252168641926,
    0.31309610341510852776,
    0.027918383235078066110,
    -0.22959284159390709415,
    0.13096206107716486317,
    -0.26973340565451071434,
    0.074973343155891435666,
    0.11199342399981020489,
    0.36613344954622675119,
    -0.39910563013603589788,
    0.10308739852747107732,
    0.41143087395589023782,
    -0.0048663605831352617622,
    -0.39203335370863990645,
    0.051942502962449647037,
    0.050665090759924496336,
    0.049674370639729879055});
inline constexpr double sofroniou_spaletta10_middle = 0.049317735759594537918;
inline constexpr auto sofroniou_spaletta10 = strang_dkd(sofroniou_spaletta10_weights);

// The table type (catalogue.hpp).
struct SofroniouSpaletta10 {
  static constexpr std::string_view tag = "ss10", title = "Sofroniou-Spaletta p10 s35",
                                    citation = "Sofroniou-Spaletta 2005";
  static constexpr int order = 10, stages = 35;
  static constexpr const auto& table = sofroniou_spaletta10;
};

}  // namespace bodypoint::splitting
