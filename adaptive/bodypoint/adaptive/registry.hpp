// bodypoint: the time-transformed and regularised methods of adaptive/, for the method registry.
#pragma once

#include "bodypoint/run.hpp"

#include <vector>

namespace bodypoint::adaptive {

/// logh-*, ttl-* and ks, in listing order.
std::vector<MethodInfo> methods();

}  // namespace bodypoint::adaptive
