// bodypoint: choose_method (methods.hpp) for a tolerance already checked, for integrate(), which
// checks every part of a request once. Not installed.
#pragma once

#include "bodypoint/methods.hpp"

#include <string>
#include <vector>

namespace bodypoint::detail {

const MethodInfo& choose_method_for(const Body& body, const std::vector<Centre>& centres, double tol, std::string* why);

}  // namespace bodypoint::detail
