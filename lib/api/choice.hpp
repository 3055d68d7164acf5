// bodypoint: choose_method (methods.hpp) for a tolerance already checked, for integrate(), which
// checks every part of a request once. Not installed.
#pragma once

#include "bodypoint/methods.hpp"

#include <string>
#include <string_view>
#include <vector>

namespace bodypoint::detail {

const MethodInfo& choose_method_for(const Body& body, const std::vector<Centre>& centres, double tol, std::string* why);

/// The catalogue's first method (listing order) of `family` applying the composition `table` (empty: any)
/// that accepts the scene, or else its first of that family and table, whose refusal then says why; nullptr
/// where the catalogue has none. logH precedes TTL in the listing, so a repelling scene gets logH.
const MethodInfo* method_of(Family family, std::string_view table, const Body& body, const std::vector<Centre>& centres);

}  // namespace bodypoint::detail
