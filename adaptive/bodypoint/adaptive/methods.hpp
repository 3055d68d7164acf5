// bodypoint: the adaptive layer's methods, time-transformed (logh-*, ttl-*) and regularised (ks). The
// registry one layer up (bodypoint/methods.hpp) lists them after the core layer's.
#pragma once

#include "bodypoint/run.hpp"

#include <vector>

namespace bodypoint::adaptive {

/// logh-*, ttl-* and ks, in listing order.
std::vector<MethodInfo> methods();

/// The constant c of the time-step function chosen from the scene and the fictitious step ds when
/// RunOptions::omega_c < 0 (run.cpp says why).
double automatic_omega_c(const Body& body, const std::vector<Centre>& centres, double ds);

}  // namespace bodypoint::adaptive
