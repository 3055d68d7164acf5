// bodypoint: SUNDIALS CVODE as a peer (built when SUNDIALS is found: BODYPOINT_HAVE_SUNDIALS).
#pragma once

#include "bodypoint/run.hpp"

namespace bodypoint {

RunResult run_cvode_adams(const Body&, const std::vector<Centre>&, const Advance&, const RunOptions&);

}  // namespace bodypoint
