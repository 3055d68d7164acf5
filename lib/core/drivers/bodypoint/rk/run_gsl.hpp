// bodypoint: GSL's controlled Runge-Kutta steppers (built when GSL is found: BODYPOINT_HAVE_GSL).
#pragma once

#include "bodypoint/run.hpp"

namespace bodypoint {

RunResult run_gsl_rk8pd(const Body&, const std::vector<Centre>&, const Advance&, const RunOptions&);
RunResult run_gsl_rkf45(const Body&, const std::vector<Centre>&, const Advance&, const RunOptions&);

}  // namespace bodypoint
