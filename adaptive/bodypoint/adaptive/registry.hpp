// bodypoint: the time-transformed and regularised methods of adaptive/, for the method registry.
#pragma once

#include "bodypoint/run.hpp"

#include <vector>

namespace bodypoint::adaptive {

/// logh-*, ttl-* and ks, in listing order.
std::vector<MethodInfo> methods();

/// The constant c of the time-step function chosen from the scene when RunSpec::omega_c < 0.
double automatic_omega_c(const Body& body, const std::vector<Centre>& centres);

}  // namespace bodypoint::adaptive
