// bodypoint: integrate() for a request whose every part was checked already (integrate.cpp's check_request,
// or validate_sweep for every point of a sweep): a sweep's tasks run it without checking their scene again.
// Internal to the API.
#pragma once

#include "bodypoint/bodypoint.hpp"

#include <vector>

namespace bodypoint::detail {

/// integrate_body without its checks: the scene, the way of advancing, the options and the events are valid
/// (the method's refusal of the scene is still its outcome, refused).
BodyResult integrate_checked(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                             const Advance& how, const Options& options);

}  // namespace bodypoint::detail
