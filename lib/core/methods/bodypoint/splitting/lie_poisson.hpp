// bodypoint: the exact Lie-Poisson sub-flows of H = T(K1, K2) + Pi(R).
//
// docs/physics.md "Exact Lie-Poisson splitting". With Omega = -(B/D) K1 (constant during a drift):
//
//   kinetic drift for tau:  K1 const,  dK2/dt = Omega x K2  (K2 precesses about K1),
//     K2(tau) = K2 + tau S1(phi) u + tau^2 C1(phi) W,                u = Omega x K2, W = Omega x u,
//     R(tau)  = R + tau (J K1 - B K2)/D - (B/D) [tau^2 C1(phi) u + tau^3 S3(phi) W],
//   with phi = |Omega| tau, S1 = sin(phi)/phi, C1 = (1 - cos phi)/phi^2, S3 = (phi - sin phi)/phi^3
//   (the R line is the integral of dR/dt = (J K1 - B K2(t))/D). All three are even, entire
//   functions of phi, evaluated from phi^2 by their Taylor series for phi < 1 and in closed form
//   otherwise, so |K1| -> 0 and B -> 0 are smooth and no division by |K1| occurs.
//
//   potential kick for tau:  R, K2 const,  K1 += tau F(R).
//
// Both flows conserve K2Q = R x K1 + K2 and |K2|^2 exactly. A material point (Spin = false,
// B = 0) skips the rotation: the drift is R += tau K1/m.
// R and K1 are accumulated with Kahan's compensated summation so that long runs of
// high-order methods reach a round-off floor near 1e-15 relative instead of growing with sqrt(n) eps.
// |K2|^2 is a Casimir of the flow; rounding in each rotation would let it random-walk by
// ~eps sqrt(rotations) (1.3e-13 after 5e5 rotations), so after each rotation K2 is rescaled to its
// initial length by a first-order factor 1 + (|K2_0|^2 - |K2|^2)/(2 |K2_0|^2), a change of O(eps).
#pragma once

#include "bodypoint/model.hpp"

#include <array>
#include <cmath>
#include <type_traits>

namespace bodypoint::splitting {

/// (R, K1, K2) with compensation terms for R and K1.
struct LieState {
  Vec3 R = Vec3::Zero();
  Vec3 K1 = Vec3::Zero();
  Vec3 K2 = Vec3::Zero();
  Vec3 R_err = Vec3::Zero();
  Vec3 K1_err = Vec3::Zero();
  double K2sq0 = 0.0;           ///< |K2|^2 at the start, the length every rotation keeps
  double half_inv_K2sq0 = 0.0;  ///< 1/(2 |K2_0|^2), or 0 when K2 = 0
};

inline LieState to_lie(const Momenta& q) {
  const double n2 = q.K2.squaredNorm();
  return {q.R, q.K1, q.K2, Vec3::Zero(), Vec3::Zero(), n2, n2 > 0.0 ? 0.5 / n2 : 0.0};
}
/// The represented values: Kahan's err holds what was added in excess, so the sum is x - err.
inline Momenta from_lie(const LieState& x) { return {x.R - x.R_err, x.K1 - x.K1_err, x.K2}; }

/// x += dx with Kahan compensation; err accumulates the excess that rounding added to x (a vector, or a
/// time: the time-transformed kernels' and ks's physical time).
template <class V>
inline void compensated_add(V& x, V& err, const std::type_identity_t<V>& dx) {
  const V y = dx - err;
  const V t = x + y;
  err = (t - x) - y;
  x = t;
}

/// S1 = sin(phi)/phi, C1 = (1 - cos phi)/phi^2, S3 = (phi - sin phi)/phi^3 from x = phi^2.
struct DriftFunctions {
  double S1, C1, S3;
};

namespace detail {
/// (-1)^k/(2k+n)! for n = 1, 2, 3 and k = 0..8.
struct SeriesCoefficients {
  double s1[9], c1[9], s3[9];
};
constexpr SeriesCoefficients series_coefficients() {
  SeriesCoefficients c{};
  double inv_fact[22]{};
  inv_fact[0] = 1.0;
  for (int n = 1; n < 22; ++n) inv_fact[n] = inv_fact[n - 1] / n;
  for (int k = 0; k < 9; ++k) {
    const double sign = (k % 2 == 0) ? 1.0 : -1.0;
    c.s1[k] = sign * inv_fact[2 * k + 1];
    c.c1[k] = sign * inv_fact[2 * k + 2];
    c.s3[k] = sign * inv_fact[2 * k + 3];
  }
  return c;
}
inline constexpr SeriesCoefficients kSeries = series_coefficients();

/// Horner evaluation of the first Terms terms of the three series at x.
template <int Terms>
inline DriftFunctions drift_series(double x) {
  double s1 = kSeries.s1[Terms - 1], c1 = kSeries.c1[Terms - 1], s3 = kSeries.s3[Terms - 1];
  for (int k = Terms - 2; k >= 0; --k) {
    s1 = s1 * x + kSeries.s1[k];
    c1 = c1 * x + kSeries.c1[k];
    s3 = s3 * x + kSeries.s3[k];
  }
  return {s1, c1, s3};
}

/// The same three series by Estrin's scheme: pairs a_2j + a_2j+1 x combined with x^2, x^4, x^8, so
/// that the dependent chain is ~log2(Terms) multiply-adds deep instead of Terms - 1 (Horner's). The
/// drift sits on the integration's critical path (each stage waits for the last), so its latency, not
/// its operation count, is what a step costs. Same terms, same truncation; the rounding differs from
/// Horner's by a few units in the last place.
template <int Terms>
inline double estrin(const double* a, double x, double x2, double x4, double x8) {
  static_assert(Terms == 6 || Terms == 9, "written out for the drift's 6- and 9-term branches");
  const double p0 = a[0] + a[1] * x, p1 = a[2] + a[3] * x, p2 = a[4] + a[5] * x;
  if constexpr (Terms == 6) {
    (void)x8;
    return (p0 + p1 * x2) + p2 * x4;
  } else {
    const double p3 = a[6] + a[7] * x;
    return ((p0 + p1 * x2) + (p2 + p3 * x2) * x4) + a[8] * x8;
  }
}

template <int Terms>
inline DriftFunctions drift_estrin(double x) {
  const double x2 = x * x, x4 = x2 * x2, x8 = x4 * x4;
  return {estrin<Terms>(kSeries.s1, x, x2, x4, x8), estrin<Terms>(kSeries.c1, x, x2, x4, x8),
          estrin<Terms>(kSeries.s3, x, x2, x4, x8)};
}
}  // namespace detail

inline DriftFunctions drift_functions(double x) {
  // Taylor series S1 = sum (-x)^k/(2k+1)!, C1 = sum (-x)^k/(2k+2)!, S3 = sum (-x)^k/(2k+3)!, cut where
  // the first omitted term of S3 (the slowest) is below 1e-19 of its value 1/6:
  //   x < 1e-3: 4 terms (x^4/11! < 3e-20),  x < 0.1: 6 terms (x^6/15! < 8e-19),  x < 1: 9 terms
  //   (x^9/21! < 2e-20). Typical steps (phi = |Omega| tau ~ 1e-2) take the 4-term branch.
  if (x < 1e-3) return detail::drift_series<4>(x);
  //   The 4-term branch stays Horner's (three dependent steps; the batch kernels repeat its bits).
  if (x < 0.1) return detail::drift_estrin<6>(x);
  if (x < 1.0) return detail::drift_estrin<9>(x);
  const double phi = std::sqrt(x);
  const double s = std::sin(phi);
  const double c = std::cos(phi);
  return {s / phi, (1.0 - c) / x, (phi - s) / (x * phi)};
}

/// The spin part of the kinetic drift for tau, shared by the Lie-Poisson drift and the Kepler split's
/// spin-orbit flow: K2 turns about K1 (Omega = -(B/D) K1, BD = B/D), rescaled to its initial length,
/// and the returned vector is what the turning adds to R beyond the straight -(B/D) tau K2(0):
/// -(B/D) [tau^2 C1 u + tau^3 S3 W] (file comment).
inline Vec3 precess(LieState& x, double BD, double tau) {
  const Vec3 Omega = -BD * x.K1;
  const Vec3 u = Omega.cross(x.K2);
  const Vec3 W = Omega.cross(u);
  const DriftFunctions f = drift_functions(Omega.squaredNorm() * tau * tau);
  const double t2 = tau * tau;
  const Vec3 dR = -BD * ((t2 * f.C1) * u + (t2 * tau * f.S3) * W);
  x.K2 += (tau * f.S1) * u + (t2 * f.C1) * W;
  // Added as a correction, not as a factor: 1 + delta with delta ~ 1e-16 would round to 1 or
  // 1 +- 2.2e-16 and over-correct systematically.
  x.K2 += ((x.K2sq0 - x.K2.squaredNorm()) * x.half_inv_K2sq0) * x.K2;
  return dR;
}

/// Exact drift and kick for one body-point in `Field`. `Spin = false` requires B = 0.
template <class Field, bool Spin>
struct LiePoissonKernel {
  using state_type = LieState;
  static constexpr bool mergeable = true;

  BodyPoint p;
  Field field;
  long evals = 0;

  LiePoissonKernel(const BodyPoint& bp, Field f)
      : p(bp), field(std::move(f)), inv_D_(1.0 / bp.D()), inv_m_(1.0 / bp.m) {}

  [[nodiscard]] LieState initial_state(const State& s0) const { return to_lie(to_momenta(p, s0)); }
  void begin_step(LieState&) const {}

  void drift(LieState& x, double tau) const {
    if constexpr (!Spin) {
      compensated_add(x.R, x.R_err, (tau * inv_m_) * x.K1);  // B = 0: v = K1/m
    } else {
      const Vec3 straight = (tau * inv_D_) * (p.J * x.K1 - p.B * x.K2);  // with K2 before it turns
      compensated_add(x.R, x.R_err, straight + precess(x, p.B * inv_D_, tau));
    }
  }

  /// The force at the current position (one force evaluation).
  Vec3 force(const LieState& x) {
    ++evals;
    return field.force(x.R);
  }
  /// K1 += tau F with a force already evaluated at the current position.
  void apply_kick(LieState& x, double tau, const Vec3& F) const { compensated_add(x.K1, x.K1_err, tau * F); }
  void kick(LieState& x, double tau) { apply_kick(x, tau, force(x)); }

  [[nodiscard]] State to_physical(const LieState& x) const { return to_state(p, from_lie(x)); }

 private:
  double inv_D_;
  double inv_m_;
};

}  // namespace bodypoint::splitting
