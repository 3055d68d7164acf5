// bodypoint: the independent references (reference.hpp); out of line, so that the installed header
// needs neither Boost.Odeint nor the Kepler solver.
#include "bodypoint/reference.hpp"

#include "bodypoint/kepler.hpp"
#include "bodypoint/rhs.hpp"

#include <boost/numeric/odeint/integrate/integrate_adaptive.hpp>
#include <boost/numeric/odeint/stepper/controlled_runge_kutta.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_fehlberg78.hpp>

#include <array>
#include <cmath>

namespace bodypoint {

State reference_state(const Body& body, const std::vector<Centre>& centres, double t_end, long double tol) {
  if (t_end < 0.0) {  // backwards: the time-reversed state forwards, reversed back (time_reversed)
    Body reversed = body;
    reversed.s0 = time_reversed(body.s0);
    return time_reversed(reference_state(reversed, centres, -t_end, tol));
  }
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

namespace {
using ld = long double;
using Vec3L = std::array<ld, 3>;
ld dot(const Vec3L& a, const Vec3L& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Kepler propagation in long double: (R0, v0) -> (R, v) after time t, mu = A/m (kepler.hpp).
void kepler_state_ld(ld mu, const Vec3L& R0, const Vec3L& v0, ld t, Vec3L& R, Vec3L& v) {
  const KeplerCoefficients<ld> k = kepler_flow<ld>(mu, std::sqrt(dot(R0, R0)), dot(R0, v0), dot(v0, v0), t);
  for (int i = 0; i < 3; ++i) {
    R[i] = (1.0L + k.f_minus_1) * R0[i] + k.g * v0[i];
    v[i] = k.fd * R0[i] + (1.0L + k.gd_minus_1) * v0[i];
  }
}
}  // namespace

void kepler_state(double mu, const Vec3& R0, const Vec3& v0, double t, Vec3& R, Vec3& v) {
  Vec3L r0{R0.x(), R0.y(), R0.z()}, w0{v0.x(), v0.y(), v0.z()}, r1, w1;
  kepler_state_ld(mu, r0, w0, t, r1, w1);
  R = Vec3(static_cast<double>(r1[0]), static_cast<double>(r1[1]), static_cast<double>(r1[2]));
  v = Vec3(static_cast<double>(w1[0]), static_cast<double>(w1[1]), static_cast<double>(w1[2]));
}

State kepler_body_state(const Body& body, const Centre& centre, double t) {
  const Vec3 x0 = body.s0.R - centre.c;
  Vec3L R{x0.x(), x0.y(), x0.z()}, v{body.s0.v.x(), body.s0.v.y(), body.s0.v.z()}, R1, v1;
  for (int k = 0; k < kKeplerChunks; ++k) {
    kepler_state_ld(static_cast<ld>(centre.A) / static_cast<ld>(body.p.m), R, v, static_cast<ld>(t) / kKeplerChunks, R1, v1);
    R = R1;
    v = v1;
  }
  State s;
  s.R = Vec3(static_cast<double>(R[0]), static_cast<double>(R[1]), static_cast<double>(R[2])) + centre.c;
  s.v = Vec3(static_cast<double>(v[0]), static_cast<double>(v[1]), static_cast<double>(v[2]));
  s.w = body.s0.w;
  return s;
}

State helix_state(const BodyPoint& p, const State& s0, double t) {
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
