// bodypoint: what the drivers, the catalogue and the checks of a run share beyond the core's interface
// (run.hpp): the flags a finished run is judged by (assess), the catalogue's traits of a family, the
// core's methods, the step counts of fixed and thesis-code runs, the poll stride of a cancel and the
// core's own checked run. Internal (not installed): a program outside the tree calls integrate().
#pragma once

#include "bodypoint/run.hpp"

#include <string>
#include <vector>

namespace bodypoint {

/// A Sample that owns its state, for a sink that hands a state on later than it saw it.
struct KeptSample {
  long step = 0;
  double t = 0.0;
  State s;
  double rel_dE = 0.0, rel_dK2sq = 0.0, abs_dK2Q = 0.0;
  bool inside = false;
  static KeptSample of(const Sample& x) { return {x.step, x.t, x.s, x.rel_dE, x.rel_dK2sq, x.abs_dK2Q, x.inside}; }
  [[nodiscard]] Sample sample() const { return {step, t, s, rel_dE, rel_dK2sq, abs_dK2Q, inside}; }
};
/// The output interval of any way of advancing time (0: none).
double output_interval(const Advance& how);
/// Steps between two polls of RunOptions::cancel (at most a few hundred microseconds of any method).
inline constexpr long kPollStride = 256;
/// Returns `every`, the sampling interval in steps; throws Error unless it is a count >= 1 (the one wording
/// of that rule: the API's options, simulate's --every).
long check_every(long every);
/// The catalogue's traits of a family (run.cpp): the one place that knows what each family is.
MethodTraits catalogue_traits(Family f);
/// The methods of the core layer, in listing order: Runge-Kutta and Adams-Bashforth (Odeint), the
/// step-size-controlled peers (Odeint, GSL), the thesis's schemes and the exact Lie-Poisson splittings.
const std::vector<MethodInfo>& core_methods();
/// Whether a run stayed in the regime its numbers mean something in (docs/physics.md "Resolution and
/// accuracy flags"), in order of precedence:
///   diverged    a non-finite state or invariant, or a relative energy error above kDivergedEnergy;
///   unresolved  a step turned the spin about K1 by more than kMaxSpinAngle, or the direction to a
///               centre by more than kMaxTurnAngle: the step cannot resolve the scene's time scales;
///   inaccurate  a relative energy error above the stated bound Checks::max_energy_error (default
///               kDefaultMaxEnergyError);
/// and "collision" instead of any of them after coming closer to an attracting centre than
/// kCollisionFraction of the starting distance (the fall is the cause).
struct Health {
  Outcome outcome = Outcome::ok;  ///< ok, diverged, unresolved, inaccurate or collision
  std::string why;                ///< one line for a message, empty when ok
};
/// An energy error larger than the energy itself: the numbers no longer describe the motion.
constexpr double kDivergedEnergy = 1.0;
/// A step that turns the spin by more than half a turn about K1 aliases the rotation (sampling at
/// fewer than two points per turn cannot tell it from a slower one, or from one the other way).
constexpr double kMaxSpinAngle = 3.14159265358979323846;
/// A step that turns the direction to a centre by more than a right angle: the force at the step's
/// two ends has no component along each other, so no step of this size samples the encounter.
constexpr double kMaxTurnAngle = 3.14159265358979323846 / 2.0;
/// Closer than this fraction of the starting distance to an attracting centre is a fall onto it.
constexpr double kCollisionFraction = 1e-6;

/// What assess() holds a run to; checks_for() sets the method's and the scene's part.
struct Checks {
  double max_energy_error = kDefaultMaxEnergyError;  ///< > 0; infinity: no accuracy flag
  bool energy_is_integral = true;  ///< false under the thesis code's force law: E is not conserved there
  bool orbit_exact = false;        ///< the method's stages solve the motion about the centre exactly
  bool spin_exact = false;         ///< free flight, solved exactly by the method's drift (any spin angle)
  /// A step resolves its own inside: an extrapolated macro step (logh-bs: its n substeps are compared and
  /// extrapolated under the tolerance) or a collocation step (far-ip: its Chebyshev points sample the
  /// spin and the force, and its iteration converges or the run fails), so what one step turns the spin
  /// or the direction to a centre by does not say that a rotation went unresolved.
  bool macro_steps = false;
};
/// Throws Error unless max_energy_error is a bound assess() can hold a run to: > 0, not NaN
/// (infinity turns the accuracy flag off).
void check_energy_bound(double max_energy_error);
/// The checks for runs of `m` on a scene with these centres, with the bound max_energy_error (as
/// check_energy_bound takes it; the caller checks it once per run or sweep).
Checks checks_for(const MethodInfo& m, const std::vector<Centre>& centres,
                  double max_energy_error = kDefaultMaxEnergyError);
Health assess(const RunResult& r, const Checks& checks = {});
/// That n (at least 1), as a double, for t_end and h_max already checked: the one rule of both.
double steps_landing_on(double t_end, double h_max);

/// The thesis's published code asked for n steps of h (with t_end > 0: n = (int)(t_end / h), Java's
/// truncation) runs `i = 1; do { step; i++; } while (i < n);`: n - 1 steps of exactly h. Under
/// ForceLaw::thesis_code the commands and sweeps count steps so, to regenerate its figures as printed.
/// Throws Error when that leaves no step (n < 2) or asks for more than 1e13.
FixedSteps thesis_code_steps(double h, long steps, double t_end);
/// Checks the scene, `how` and `options` (check, check_takes), asks the method whether it accepts the
/// scene (refusal, thrown as Error), and runs. The public API's integrate() (bodypoint.hpp) is what
/// programs call; this is the core's entry for its own tests and benchmarks.
RunResult run(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres, const Advance& how,
              const RunOptions& options = {});

// --- what the commands, the catalogue and the drivers ask of a method, beyond run.hpp's ----------

/// True for the peers that bodypoint's own methods compete with: the general-purpose ones (Boost.Odeint,
/// GSL) and the time-transformed one of Mikkola's codes (logh-bs).
inline bool is_peer(const MethodInfo& m) { return m.traits.peer; }
/// Throws Error unless `m` takes this way of advancing time (FixedSteps for fixed-step methods,
/// FictitiousSteps for time-transformed ones, ControlledSteps for step-size-controlled ones; Accuracy
/// for none: it searches the step of one of the others).
void check_takes(const MethodInfo& m, const Advance& how);

/// What a loop throws when RunOptions::cancel is set: no search retries it (integrate_body: failed).
struct StoppedOnRequest : Error {
  StoppedOnRequest() : Error(kStoppedOnRequest) {}
};

}  // namespace bodypoint
