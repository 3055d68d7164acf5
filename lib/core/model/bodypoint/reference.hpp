// bodypoint: independent references a run is checked against (docs/physics.md "What to check a
// run against").
//
// - `reference_state`: Boost.Odeint's runge_kutta_fehlberg78 with step-size control, in long
//   double, on PreciseEquations (rhs.hpp), which shares no code with the production kernels.
// - `kepler_state`: the analytic two-body (Rutherford/Kepler) motion of a material point (B = 0)
//   in one centre's field, by the universal-variable form of Kepler's equation in long double
//   (kepler.hpp), valid for attraction and repulsion alike (mu = A/m of either sign).
// - `helix_state`: the exact free motion (A = 0): K1 constant, K2 rotating about K1 at rate
//   -(B/D)|K1|, R from the conservation of R x K1 + K2 (docs/physics.md, kinetic drift).
#pragma once

#include "bodypoint/model.hpp"

#include <vector>

namespace bodypoint {

/// State at t_end from s0 at t = 0, integrated in long double with relative and absolute
/// tolerance `tol`.
State reference_state(const Body& body, const std::vector<Centre>& centres, double t_end, long double tol = 1e-16L);

/// Position and velocity at time t of d^2R/dt^2 = -mu R/|R|^3 from (R0, v0); mu = A/m.
void kepler_state(double mu, const Vec3& R0, const Vec3& v0, double t, Vec3& R, Vec3& v);

/// The exact material-point state at t in one centre's field (B must be 0; w is constant).
/// Propagated in kKeplerChunks equal pieces: over one long span of a near-radial encounter R0 and v0
/// are nearly collinear and R = f R0 + g v0 loses the small transverse part to cancellation
/// (measured: 5e-8 after the pericentre of the close scene in one piece, 5e-13 in 80 pieces).
inline constexpr int kKeplerChunks = 256;
State kepler_body_state(const Body& body, const Centre& centre, double t);

/// The exact free motion (A = 0) at time t, written independently of the splitting kernel:
/// Rodrigues rotation of K2 about k = K1/|K1| by theta = -(B/D)|K1| t, and
/// R = R0 + t (J|K1| - B K2.k)/D k + K1 x (K2_0 - K2_t)/|K1|^2 (docs/physics.md, kinetic drift).
State helix_state(const BodyPoint& p, const State& s0, double t);

}  // namespace bodypoint
