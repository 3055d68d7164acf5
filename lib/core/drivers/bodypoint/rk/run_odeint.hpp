// bodypoint: the Boost.Odeint run loops (fixed-step RK4/AB4 and the step-size-controlled steppers),
// kept apart from the splitting loops of run.cpp. run_odeint.cpp says how the RK4 loop is kept as fast
// as odeint driven directly (bench_steps BM_OdeintDirect).
#pragma once

#include "bodypoint/run.hpp"

namespace bodypoint {

RunResult run_odeint_rk4(const Body&, const std::vector<Centre>&, const Advance&, const RunOptions&);
RunResult run_odeint_ab4(const Body&, const std::vector<Centre>&, const Advance&, const RunOptions&);
RunResult run_thesis_ab4(const Body&, const std::vector<Centre>&, const Advance&, const RunOptions&);
RunResult run_odeint_dopri5(const Body&, const std::vector<Centre>&, const Advance&, const RunOptions&);
RunResult run_odeint_rkf78(const Body&, const std::vector<Centre>&, const Advance&, const RunOptions&);
RunResult run_odeint_bs(const Body&, const std::vector<Centre>&, const Advance&, const RunOptions&);

}  // namespace bodypoint
