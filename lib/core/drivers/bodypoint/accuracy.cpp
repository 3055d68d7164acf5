// bodypoint: the accuracy mode's checks and the time-step constant c (accuracy.hpp).
#include "bodypoint/accuracy.hpp"

#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <cmath>

namespace bodypoint {

namespace {

/// Far from every centre the spin-orbit angle per step may be this many times the orbital angle per
/// step at closest approach (see automatic_omega_c).
constexpr double kSpinToOrbitStepRatio = 16.0;
/// The spin-orbit angle of one whole step far from every centre stays below this (radians).
constexpr double kMaxSpinAngle = 2.0;

}  // namespace

void check_tolerance(double tol) {
  require_positive(tol, "the tolerance tol");
  if (tol < kMinTolerance)
    throw Error("tol below 1e-13 cannot be delivered in double precision (the round-off of a run is "
                "1e-15..1e-13 relative)");
  if (!(tol < 1.0)) throw Error("tol must be below 1 (it is a relative error of the final state)");
}

// c = max(sum|A| Omega_so / (k v0), Omega_so ds / kMaxSpinAngle): far from every centre a step turns the
// spin by k times the orbital angle per step at closest approach, and never by more than 2 rad
// (docs/physics.md, "The time-step constant c", gives the rule's reasons and measurements).
double automatic_omega_c(const Body& body, const std::vector<Centre>& centres, double ds) {
  const BodyPoint& p = body.p;
  if (p.B == 0.0) return 0.0;
  const Momenta q = to_momenta(p, body.s0);
  const double spin_rate = std::abs(p.B) * q.K1.norm() / p.D();
  const double speed = body.s0.v.norm();
  double strength = 0.0;
  for (const Centre& c : centres) strength += std::abs(c.A);
  if (!(speed > 0.0) || !(spin_rate > 0.0)) return 0.0;
  return std::max(strength * spin_rate / (kSpinToOrbitStepRatio * speed), spin_rate * std::abs(ds) / kMaxSpinAngle);
}

}  // namespace bodypoint
