// bodypoint: a request checked once, and integrate() for a request whose every part was checked already
// (check_request, or validate_sweep for every point of a sweep): a sweep's tasks, a Stepper's segments and a
// command's runs of a scene it checked (read_scene_file, or validate where it built one) run without
// checking their scene again; and the front ends' rules of a request (the default end, omega_c). Internal
// to the API, the commands and the Python module.
#pragma once

#include "bodypoint/bodypoint.hpp"

#include <vector>

namespace bodypoint {

// --- the front ends' (the command line's, Python's) rules of a request ---------------------------

/// A time-step constant c a caller gives (RunOptions::omega_c; not giving one is -1, automatic),
/// checked for the run it is given to: a finite number >= 0, for a time-transformed method (logh-*,
/// ttl-*; ks has none) run by its fictitious step, not in the accuracy mode (which chooses c itself).
/// Error naming the quantity otherwise.
void check_time_step_constant(double omega_c, const MethodInfo* method, bool accuracy);
/// True when `request` asks the accuracy mode to choose the step of `method` (nullptr: auto).
bool searches(const MethodInfo* method, const StepRequest& request);
/// Every front end's default end (the command line's, Python's): a request with neither an end time
/// nor a count of steps runs the accuracy mode to t_end = kDefaultStep kDefaultSteps (50, the thesis's
/// h n) and any other way kDefaultSteps steps; a request with one is returned as it is.
StepRequest with_default_end(StepRequest request, const MethodInfo* method);

/// Throws Error unless max_error is a number > 0 (infinity: no bound).
void check_error_bound(double max_error);

/// Every part of a request checked once, each with one message naming the quantity: the scene
/// (validate), then what check_run checks. The one check integrate(), integrate_body() and a Stepper make.
void check_request(const Scene& scene, const MethodInfo* method, const Advance& how, const Options& options);

struct TwiceAsFar;  // encounter_parts.hpp

}  // namespace bodypoint

namespace bodypoint::detail {

/// A request whose scene was checked already: the way of advancing time and whether the method takes
/// it, the options and the events (against the scene's centres).
void check_run(const std::vector<Centre>& centres, const MethodInfo* method, const Advance& how, const Options& options);

/// integrate_body without its checks: the scene, the way of advancing, the options and the events are valid
/// (the method's refusal of the scene is still its outcome, refused).
BodyResult integrate_checked(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                             const Advance& how, const Options& options);

/// integrate_checked for an encounter run to its departure (the events of encounter_options): where auto
/// runs it, the body spins and starts far enough out, its far field is crossed by legs of one turn of the
/// spin a step (far_legs.cpp) and the run between them is auto's; otherwise integrate_checked.
/// With `twice` (the same encounter from 2L, twice_as_far_beside) where legs serve both, one run between the legs
/// serves both (run_pair_with_legs) and `twice->run` is set.
BodyResult integrate_encounter_checked(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                                       const Advance& how, const Options& options, TwiceAsFar* twice = nullptr);

}  // namespace bodypoint::detail
