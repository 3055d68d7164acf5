// bodypoint: the adaptive layer's methods, time-transformed (logh-*, ttl-*) and regularised (ks). The
// registry one layer up (bodypoint/methods.hpp) lists them after the core layer's.
#pragma once

#include "bodypoint/run.hpp"

#include <vector>

namespace bodypoint::adaptive {

/// logh-*, ttl-* and ks, in listing order.
std::vector<MethodInfo> methods();

}  // namespace bodypoint::adaptive
