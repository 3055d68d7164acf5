// bodypoint: independent references a run is checked against (docs/physics.md "What to check a
// run against").
//
// - `reference_state`: Boost.Odeint's runge_kutta_fehlberg78 with step-size control, in long
//   double, on PreciseEquations (rhs.hpp), which shares no code with the production kernels.
// - `kepler_state`: the analytic two-body (Rutherford/Kepler) motion of a material point (B = 0)
//   in one centre's field, by the universal-variable form of Kepler's equation
//   (J. M. A. Danby, Fundamentals of Celestial Mechanics, 2nd ed. 1988, sec. 6.9; Stumpff
//   functions), valid for attraction and repulsion alike (mu = A/m of either sign).
// - `helix_state`: the exact free motion (A = 0): K1 constant, K2 rotating about K1 at rate
//   -(B/D)|K1|, R from the conservation of R x K1 + K2 (docs/physics.md, kinetic drift).
#pragma once

#include "bodypoint/model.hpp"
#include "bodypoint/rhs.hpp"

#include <boost/numeric/odeint/integrate/integrate_adaptive.hpp>
#include <boost/numeric/odeint/stepper/controlled_runge_kutta.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_fehlberg78.hpp>

#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace bodypoint {

/// State at t_end from s0 at t = 0, integrated in long double with relative and absolute
/// tolerance `tol`.
inline State reference_state(const Body& body, const std::vector<Centre>& centres, double t_end,
                             long double tol = 1e-16L) {
  namespace odeint = boost::numeric::odeint;
  using S = OdeState<long double>;
  PreciseEquations<long double> sys(body.p, centres);
  S x;
  const OdeState<double> x0 = to_ode(body.s0);
  for (int i = 0; i < 9; ++i) x[i] = x0[i];
  using Rkf78 = odeint::runge_kutta_fehlberg78<S, long double>;
  using Checker = odeint::default_error_checker<long double, typename Rkf78::algebra_type,
                                                typename Rkf78::operations_type>;
#pragma GCC diagnostic push
  // GCC 12 reports odeint's default-constructed stepper members as maybe-uninitialized when the
  // controller copies them (a false positive inside Boost; the members are arrays it fills first).
#ifndef __clang__  // a GCC-only warning group
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
  odeint::controlled_runge_kutta<Rkf78> stepper{Checker(tol, tol)};
  odeint::integrate_adaptive(stepper, std::cref(sys), x, 0.0L, static_cast<long double>(t_end), 1e-3L);
#pragma GCC diagnostic pop
  OdeState<double> out;
  for (int i = 0; i < 9; ++i) out[i] = static_cast<double>(x[i]);
  return from_ode(out);
}

namespace detail {
/// Stumpff functions c0..c3 of z (Danby eq. 6.9.x), in long double.
inline void stumpff(long double z, long double c[4]) {
  if (std::abs(z) < 0.1L) {
    // Series c_n(z) = sum (-z)^k/(2k+n)!, enough terms for |z| < 0.1 to reach long double.
    for (int n = 0; n < 4; ++n) {
      long double term = 1.0L, sum = 0.0L;
      for (int j = 1; j <= n; ++j) term /= j;
      for (int k = 0; k < 20; ++k) {
        sum += term;
        term *= -z / ((2 * k + n + 1) * (2 * k + n + 2));
      }
      c[n] = sum;
    }
    return;
  }
  if (z > 0) {
    const long double s = std::sqrt(z);
    c[0] = std::cos(s);
    c[1] = std::sin(s) / s;
  } else {
    const long double s = std::sqrt(-z);
    c[0] = std::cosh(s);
    c[1] = std::sinh(s) / s;
  }
  c[2] = (1.0L - c[0]) / z;
  c[3] = (1.0L - c[1]) / z;
}
}  // namespace detail

namespace detail {
using ld = long double;
using Vec3L = std::array<ld, 3>;
inline ld dot(const Vec3L& a, const Vec3L& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Kepler propagation in long double: (R0, v0) -> (R, v) after time t, mu = A/m.
inline void kepler_state_ld(ld mu, const Vec3L& R0, const Vec3L& v0, ld t, Vec3L& R, Vec3L& v) {
  const ld r0 = std::sqrt(dot(R0, R0));
  const ld sigma0 = dot(R0, v0);
  const ld beta = 2.0L * mu / r0 - dot(v0, v0);  // -2 x energy per mass
  auto G = [&](ld s, ld g[4]) {
    ld c[4];
    detail::stumpff(beta * s * s, c);
    g[0] = c[0];
    g[1] = s * c[1];
    g[2] = s * s * c[2];
    g[3] = s * s * s * c[3];
  };
  // Solve t = r0 G1 + sigma0 G2 + mu G3 for s; dt/ds = r(s) > 0. Start from a lower bound,
  // s >= t/(r0 + v_max t) with v_max^2 = |v0|^2 + 2|mu|/r0 (r grows at most that fast), and double:
  // a first guess like t/r0 overshoots by orders of magnitude when the start is near the centre,
  // and cosh of the overshoot overflows.
  ld g[4];
  auto tof = [&](ld s) {
    G(s, g);
    return r0 * g[1] + sigma0 * g[2] + mu * g[3];
  };
  const ld v_max = std::sqrt(dot(v0, v0) + 2.0L * std::abs(mu) / r0);
  ld lo = 0.0L, hi = t / (r0 + v_max * t);
  while (tof(hi) < t) {
    lo = hi;
    hi *= 2.0L;
    if (!(hi < 1e6L)) throw std::runtime_error("kepler_state: no bracket");
  }
  ld s = 0.5L * (lo + hi);
  for (int it = 0; it < 400; ++it) {
    const ld f = tof(s) - t;
    const ld r = r0 * g[0] + sigma0 * g[1] + mu * g[2];
    if (f > 0) hi = s; else lo = s;
    ld next = s - f / r;
    if (!(next > lo && next < hi)) next = 0.5L * (lo + hi);
    if (std::abs(next - s) <= 4e-19L * std::abs(s) || hi - lo <= 4e-19L * hi) {
      s = next;
      break;
    }
    s = next;
  }
  G(s, g);
  const ld r = r0 * g[0] + sigma0 * g[1] + mu * g[2];
  const ld f = 1.0L - mu * g[2] / r0, gg = t - mu * g[3];
  const ld fd = -mu * g[1] / (r0 * r), gd = 1.0L - mu * g[2] / r;
  for (int i = 0; i < 3; ++i) {
    R[i] = f * R0[i] + gg * v0[i];
    v[i] = fd * R0[i] + gd * v0[i];
  }
}
}  // namespace detail

/// Position and velocity at time t of d^2R/dt^2 = -mu R/|R|^3 from (R0, v0); mu = A/m.
inline void kepler_state(double mu, const Vec3& R0, const Vec3& v0, double t, Vec3& R, Vec3& v) {
  detail::Vec3L r0{R0.x(), R0.y(), R0.z()}, w0{v0.x(), v0.y(), v0.z()}, r1, w1;
  detail::kepler_state_ld(mu, r0, w0, t, r1, w1);
  R = Vec3(static_cast<double>(r1[0]), static_cast<double>(r1[1]), static_cast<double>(r1[2]));
  v = Vec3(static_cast<double>(w1[0]), static_cast<double>(w1[1]), static_cast<double>(w1[2]));
}


/// The exact material-point state at t in one centre's field (B must be 0; w is constant).
/// Propagated in kKeplerChunks equal pieces: over one long span of a near-radial encounter R0 and v0
/// are nearly collinear and R = f R0 + g v0 loses the small transverse part to cancellation
/// (measured: 5e-8 after the pericentre of the close scene in one piece, 5e-13 in 80 pieces).
inline constexpr int kKeplerChunks = 256;
inline State kepler_body_state(const Body& body, const Centre& centre, double t) {
  using detail::ld;
  const Vec3 x0 = body.s0.R - centre.c;
  detail::Vec3L R{x0.x(), x0.y(), x0.z()}, v{body.s0.v.x(), body.s0.v.y(), body.s0.v.z()}, R1, v1;
  for (int k = 0; k < kKeplerChunks; ++k) {
    detail::kepler_state_ld(static_cast<ld>(centre.A) / static_cast<ld>(body.p.m), R, v,
                            static_cast<ld>(t) / kKeplerChunks, R1, v1);
    R = R1;
    v = v1;
  }
  State s;
  s.R = Vec3(static_cast<double>(R[0]), static_cast<double>(R[1]), static_cast<double>(R[2])) + centre.c;
  s.v = Vec3(static_cast<double>(v[0]), static_cast<double>(v[1]), static_cast<double>(v[2]));
  s.w = body.s0.w;
  return s;
}

/// The exact free motion (A = 0) at time t, written independently of the splitting kernel:
/// Rodrigues rotation of K2 about k = K1/|K1| by theta = -(B/D)|K1| t, and
/// R = R0 + t (J|K1| - B K2.k)/D k + K1 x (K2_0 - K2_t)/|K1|^2 (docs/physics.md, kinetic drift).
inline State helix_state(const BodyPoint& p, const State& s0, double t) {
  const Momenta q0 = to_momenta(p, s0);
  const double k1 = q0.K1.norm();
  const Vec3 k = q0.K1 / k1;
  const double theta = -(p.B / p.D()) * k1 * t;
  const Vec3& K2 = q0.K2;
  const Vec3 K2t = K2 * std::cos(theta) + k.cross(K2) * std::sin(theta) + k * k.dot(K2) * (1.0 - std::cos(theta));
  Momenta q;
  q.K1 = q0.K1;
  q.K2 = K2t;
  q.R = q0.R + (t * (p.J * k1 - p.B * K2.dot(k)) / p.D()) * k + q0.K1.cross(K2 - K2t) / (k1 * k1);
  return to_state(p, q);
}

}  // namespace bodypoint
