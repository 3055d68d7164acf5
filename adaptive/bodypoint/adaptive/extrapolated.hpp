// bodypoint: logh-bs, the logarithmic-Hamiltonian leapfrog with Bulirsch-Stoer extrapolation and a
// tolerance per step (extrapolated.cpp): the time-transformed peer of Mikkola's codes.
#pragma once

#include "bodypoint/run.hpp"

#include <string>
#include <vector>

namespace bodypoint::adaptive {

/// Runs logh-bs with ControlledSteps: tol per macro step, h0 the first physical step, to t_end exactly.
RunResult run_logh_bs(const Body& body, const std::vector<Centre>& centres, const Advance& how,
                      const RunOptions& options);
/// Why logh-bs refuses a scene ("" when it runs it): Coulomb's law, every centre repulsive.
std::string logh_bs_check(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres);

}  // namespace bodypoint::adaptive
