// bodypoint: a request checked once, and integrate() for a request whose every part was checked already
// (check_request, or validate_sweep for every point of a sweep): a sweep's tasks, a Stepper's segments and a
// command's runs of a scene it checked (read_scene_file, or validate where it built one) run without
// checking their scene again. Internal to the API and the commands.
#pragma once

#include "bodypoint/bodypoint.hpp"

#include <vector>

namespace bodypoint {

/// Throws Error unless max_error is a number > 0 (infinity: no bound).
void check_error_bound(double max_error);

/// Whether `method` takes a time-step constant c (RunOptions::omega_c): the time-transformed methods
/// logh-* and ttl-*, not ks (regularised, exact in its fictitious time).
bool takes_time_step_constant(const MethodInfo& method);

/// Every part of a request checked once, each with one message naming the quantity: the scene
/// (validate), then what check_run checks. The one check integrate(), integrate_body() and a Stepper make.
void check_request(const Scene& scene, const MethodInfo* method, const Advance& how, const Options& options);

}  // namespace bodypoint

namespace bodypoint::detail {

/// A request whose scene was checked already: the way of advancing time and whether the method takes
/// it, the options and the events (against the scene's centres).
void check_run(const std::vector<Centre>& centres, const MethodInfo* method, const Advance& how, const Options& options);

/// integrate_body without its checks: the scene, the way of advancing, the options and the events are valid
/// (the method's refusal of the scene is still its outcome, refused).
BodyResult integrate_checked(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                             const Advance& how, const Options& options);

}  // namespace bodypoint::detail
