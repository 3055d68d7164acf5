// bodypoint: the catalogue of every method, part of the public API (bodypoint.hpp).
//
// Layers, each a CMake target that depends only on the ones below it:
//   bodypoint_core      lib/core/        model, fields, invariants, tables, composition engine,
//                                        kernels, fixed-step and peer drivers (core_methods)
//   bodypoint_adaptive  adaptive/        time-transformed and regularised methods and their driver
//                                        (adaptive::methods), the accuracy mode's step search
//   bodypoint           lib/api/         this catalogue, --method auto, integrate() and Stepper
//   bodypoint_commands  experiments/     the command line
// Nothing below this header includes it.
#pragma once

#include "bodypoint/run.hpp"

#include <string>
#include <string_view>
#include <vector>

namespace bodypoint {

/// Every method, in the order `bodypoint methods` lists them: the core layer's, then the adaptive
/// layer's.
const std::vector<MethodInfo>& methods();

/// The method called `name`, or nullptr.
const MethodInfo* find_method(std::string_view name);

/// Throws Error("unknown method ...") for a name not in methods(), worded as every unknown name: the
/// name within two edits of it (letters compared without case), then the valid ones.
const MethodInfo& method_or_throw(std::string_view name);

/// The methods a list names: "all", "fixed" (every fixed-step method but the Kepler split, whose stage
/// is a Kepler solve, and the far-field collocation, whose step is tens of radians of spin, not the
/// thesis's h: the thesis's studies' set) or names separated by commas. Error for an unknown
/// name or an empty list.
std::vector<const MethodInfo*> methods_named(std::string_view list);

/// `--method auto`: a one-centre material point: ks; a body far from every centre for the whole run
/// (straight-line estimate of the closest approach, potential there below the time-step constant c):
/// Lie-Poisson; only repelling centres: logH; any attracting centre: TTL. The composition table, from tol
/// 1e-4 to 1e-8, is the one whose whole search was measured cheapest (bench/auto_costs: Verlet to about
/// 2e-5, Yoshida 4 near 1e-5, PEFRL from about 1e-6 to 1e-8); Kahan-Li 6 down to 1e-10, Kahan-Li 8 below.
/// `why` receives one line saying what was chosen and why.
const MethodInfo& choose_method(const Body& body, const std::vector<Centre>& centres, double tol, std::string* why);

/// Whether the accuracy mode checks auto's answer against a companion at a finer step (1/1.25 of it), as
/// it checks a method the user named: about several centres. Unverified there, every table auto may choose missed
/// TOL on some scene (bench/estimate_grid.py --branches, TOL 1e-5 to 1e-9: ttl-kl6 at 1e-8 delivered
/// 5.7e-8 with an estimate of 6.6e-10); verified, none did.
bool auto_verifies(const std::vector<Centre>& centres);

}  // namespace bodypoint
