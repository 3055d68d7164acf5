// bodypoint: the Kepler split of H = T(K1, K2) + Pi(R) for one Coulomb centre (docs/physics.md,
// "Kepler split").
//
// With T = J|K1|^2/(2D) - B K1.K2/D + m|K2|^2/(2D) the Hamiltonian is a sum of two exactly solvable parts:
//
//   H_K = J|K1|^2/(2D) + Pi(R)          the Kepler problem of a particle of mass D/J:
//                                       d^2R/dt^2 = (J/D) F(R), mu = J A/D (kepler.hpp); K2 constant;
//   H_S = -B K1.K2/D + m|K2|^2/(2D)     the spin-orbit part: K1 constant, K2 precesses about K1 at
//                                       -(B/D)|K1| (m|K2|^2 is a Casimir: it moves nothing), and R
//                                       follows dR/dt = -B K2(t)/D.
//
// H_S's flow is the exact Lie-Poisson drift (lie_poisson.hpp) without its straight part tau J K1/D.
// Both flows conserve K2Q = (R - c) x K1 + K2 (H_K is central, H_S is the drift's rotation) and |K2|^2,
// so every composition does too. A material point (B = 0) has H_S = 0: one Kepler flow per step is
// the exact motion, whatever the step. For B != 0 the splitting error comes only from the coupling:
// {H_K, H_S} = (B/D) F.K2, no error from the Kepler motion itself (the force's own curvature, which the
// Lie-Poisson split pays for near the centre).
//
// The engine's "kick" is the Kepler flow and its "drift" the spin-orbit flow, so a table's stages are
// Kepler solves (counted as force evaluations). With several centres the first is the Kepler centre
// and the others' potential is a third part, H_O = sum_{k>0} Pi_k(R), whose flow is a kick
// K1 += tau F_O(R); the three-part methods are the tables' compositions with each Kepler flow
// flanked by two half kicks of H_O (composition.hpp, flatten_three), of the tables' orders.
// K2Q is then not conserved (several centres), |K2|^2 still is.
#pragma once

#include "bodypoint/field.hpp"
#include "bodypoint/kepler.hpp"
#include "bodypoint/model.hpp"
#include "bodypoint/splitting/lie_poisson.hpp"

#include <cmath>
#include <cstddef>
#include <type_traits>

namespace bodypoint::splitting {

/// The Kepler flow about c over |tau| (tau < 0: the forward flow of the reversed velocity) of a position R and a
/// momentum P (velocity u_per_P P) each held as a compensated pair (value, err: compensated_add). The flow's
/// inputs r0, sigma0, |u0|^2 and its increments are taken in KeplerWide<double> from the pairs and each
/// increment is rounded once: the flow is that of the state the pairs hold. Taken from the pairs rounded to
/// double (the flow of a state one rounding off, added to the pair), the energy of kep-y4's Kepler stages
/// drifted one way, 7.7e-4 unit roundoffs a step (docs/measurements.md, "Long-time behaviour").
inline void kepler_flow_compensated(double mu, double u_per_P, const Vec3& c, Vec3& R, Vec3& R_err, Vec3& P, Vec3& P_err,
                                    double tau) {
  using W = KeplerWide<double>;
  const W sign = tau < 0.0 ? -1.0 : 1.0;
  W X0[3], U0[3], r0sq = 0, sigma0 = 0, v0sq = 0;
  for (int i = 0; i < 3; ++i) {
    X0[i] = (W(R[i]) - W(R_err[i])) - W(c[i]);
    U0[i] = sign * W(u_per_P) * (W(P[i]) - W(P_err[i]));
    r0sq += X0[i] * X0[i];
    sigma0 += X0[i] * U0[i];
    v0sq += U0[i] * U0[i];
  }
  const KeplerCoefficients<W> k = kepler_flow_wide(mu, std::sqrt(r0sq), sigma0, v0sq, std::abs(tau));
  Vec3 dR, dP;
  for (int i = 0; i < 3; ++i) {
    dR[i] = static_cast<double>(k.f_minus_1 * X0[i] + k.g * U0[i]);
    dP[i] = static_cast<double>(sign * (k.fd * X0[i] + k.gd_minus_1 * U0[i]) / W(u_per_P));
  }
  compensated_add(R, R_err, dR);
  compensated_add(P, P_err, dP);
}

template <class Field, bool Spin>
struct KeplerSplitKernel {
  using state_type = LieState;
  /// A Kepler flow is not a force applied to the momenta: consecutive steps share nothing.
  static constexpr bool mergeable = false;

  BodyPoint p;
  Field field;
  long evals = 0;

  KeplerSplitKernel(const BodyPoint& bp, Field f) : p(bp), field(std::move(f)), inv_D_(1.0 / bp.D()) {
    const Centre one = only_centre(field);
    c_ = one.c;
    mu_ = bp.J * one.A * inv_D_;
    u_per_K1_ = bp.J * inv_D_;
  }

  [[nodiscard]] LieState initial_state(const State& s0) const { return to_lie(to_momenta(p, s0)); }
  void begin_step(LieState&) const {}

  /// H_S for tau: the Lie-Poisson drift's rotation and its R part, without the straight J K1/D.
  void drift(LieState& x, double tau) const {
    if constexpr (Spin) {
      const double BD = p.B * inv_D_;
      const Vec3 straight = (-BD * tau) * x.K2;  // with K2 before it turns
      compensated_add(x.R, x.R_err, straight + precess(x, BD, tau));
    } else {
      (void)x;
      (void)tau;
    }
  }

  /// H_K for tau (> 0 or < 0: a flow backwards in time is the forward flow of the reversed velocity).
  void kick(LieState& x, double tau) {
    ++evals;
    kepler_flow_compensated(mu_, u_per_K1_, c_, x.R, x.R_err, x.K1, x.K1_err, tau);
  }

  /// H_O for tau: K1 += tau F(R) of every centre but the Kepler one (several centres only).
  void third(LieState& x, double tau) const {
    if constexpr (std::is_same_v<Field, CentreList>) {
      const Vec3 R = x.R - x.R_err;
      Vec3 F = Vec3::Zero();
      for (std::size_t k = 1; k < field.centres.size(); ++k) {
        const Centre& c = field.centres[k];
        const Vec3 d = R - c.c;
        const double inv_r = 1.0 / d.norm();
        F -= (c.A * inv_r * inv_r * inv_r) * d;
      }
      compensated_add(x.K1, x.K1_err, tau * F);
    } else {
      (void)x;
      (void)tau;
    }
  }

  [[nodiscard]] State to_physical(const LieState& x) const { return to_state(p, from_lie(x)); }

 private:
  static Centre only_centre(const Field& f) {
    if constexpr (std::is_same_v<Field, OriginCentre>) {
      return Centre{Vec3::Zero(), f.A};
    } else {
      return f.centres.front();
    }
  }

  double inv_D_;
  Vec3 c_ = Vec3::Zero();
  double mu_ = 0.0;
  double u_per_K1_ = 0.0;
};

}  // namespace bodypoint::splitting
