// bodypoint: right-hand side of the equations of motion, usable as a Boost.Odeint system.
//
// docs/physics.md "Equations of motion" (the thesis's eq. 1.9 and the corrected eq. 1.10):
//   D dv/dt = J F(R) - B^2 (w x v)
//   D dw/dt = -B F(R) + m B (w x v)
//   dR/dt   = v
// with F = -A (R - c)/|R - c|^3 summed over centres. Erratum 1: the thesis prints the second line
// with both signs flipped, which breaks dK1/dt = F; tests/lib/test_model.cpp checks the identity.
//
// Odeint state layout: x = (R, v, w), nine scalars. PreciseEquations is the system a program drives
// Boost.Odeint with (any scalar type); the production kernels' system over a field
// (EquationsOfMotion) is internal: detail/equations.hpp.
#pragma once

#include "bodypoint/model.hpp"

#include <array>
#include <cmath>
#include <vector>

namespace bodypoint {

template <class Scalar>
using OdeState = std::array<Scalar, 9>;

inline OdeState<double> to_ode(const State& s) {
  return {s.R.x(), s.R.y(), s.R.z(), s.v.x(), s.v.y(), s.v.z(), s.w.x(), s.w.y(), s.w.z()};
}
inline State from_ode(const OdeState<double>& x) {
  return {Vec3(x[0], x[1], x[2]), Vec3(x[3], x[4], x[5]), Vec3(x[6], x[7], x[8])};
}

/// The same equations in any floating type, with a plain loop over centres. It shares no code
/// with the double-precision kernels so that it can serve as an independent reference
/// (run it in long double with a tight tolerance; see reference.hpp).
template <class Scalar>
struct PreciseEquations {
  Scalar m, B, J;
  std::vector<std::array<Scalar, 5>> centres;  ///< (cx, cy, cz, A, 1 for the thesis code's |R|^1.5 law)

  PreciseEquations(const BodyPoint& p, const std::vector<Centre>& cs)
      : m(p.m), B(p.B), J(p.J) {
    for (const Centre& k : cs)
      centres.push_back({k.c.x(), k.c.y(), k.c.z(), k.A, Scalar(k.law == ForceLaw::coulomb ? 0 : 1)});
  }

  void operator()(const OdeState<Scalar>& x, OdeState<Scalar>& dxdt, Scalar /*t*/) const {
    Scalar F[3] = {0, 0, 0};
    for (const auto& k : centres) {
      const Scalar d[3] = {x[0] - k[0], x[1] - k[1], x[2] - k[2]};
      const Scalar r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      const Scalar s = k[4] == 0 ? -k[3] / (r2 * std::sqrt(r2)) : -k[3] / std::sqrt(std::sqrt(r2) * r2);
      for (int i = 0; i < 3; ++i) F[i] += s * d[i];
    }
    const Scalar* v = &x[3];
    const Scalar* w = &x[6];
    const Scalar wxv[3] = {w[1] * v[2] - w[2] * v[1], w[2] * v[0] - w[0] * v[2],
                           w[0] * v[1] - w[1] * v[0]};
    const Scalar D = m * J - B * B;
    for (int i = 0; i < 3; ++i) {
      dxdt[i] = v[i];
      dxdt[3 + i] = (J * F[i] - B * B * wxv[i]) / D;
      dxdt[6 + i] = (-B * F[i] + m * B * wxv[i]) / D;
    }
  }
};

}  // namespace bodypoint
