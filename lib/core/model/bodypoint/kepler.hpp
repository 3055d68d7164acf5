// bodypoint: the two-body flow d^2X/dt^2 = -mu X/|X|^3 over a time t, by the universal-variable form
// of Kepler's equation (J. M. A. Danby, Fundamentals of Celestial Mechanics, 2nd ed. 1988, sec. 6.9;
// Stumpff functions), valid for attraction (mu > 0) and repulsion (mu < 0) alike.
//
// With beta = 2 mu/r0 - v0.v0 and G_n(s) = s^n c_n(beta s^2), the universal variable s solves
//   t = r0 G1 + sigma0 G2 + mu G3,   sigma0 = X0.v0,   dt/ds = r(s) = r0 G0 + sigma0 G1 + mu G2 > 0,
// and X = f X0 + g v0, v = fd X0 + gd v0 with f = 1 - mu G2/r0, g = t - mu G3 = r0 G1 + sigma0 G2, fd = -mu G1/(r0 r),
// gd = 1 - mu G2/r. `kepler_flow` returns the increments f - 1, g, fd, gd - 1 (so that a caller adds
// X += (f - 1) X0 + g v0 without the cancellation of f X0 - X0 for short steps).
//
// One template serves the long-double oracle (reference.hpp) and the Kepler split (kepler_split.hpp).
#pragma once

#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>

namespace bodypoint {

/// Below this |z| the series of the Stumpff functions is summed (remainder below 0.1^12/25! ~ 1e-37 with
/// 12 terms, far under long double's 1e-19).
inline constexpr double kStumpffSeriesBelow = 0.1;
/// From this |z| on the closed forms are used: there 1 - c1 >= 0.16 and 1 - c0 >= 0.46, so c2 = (1 - c0)/z
/// and c3 = (1 - c1)/z lose a few roundings at most. Between the two, z is quartered down to the series
/// (at most twice) and the arguments quadrupled back (Danby's relations, below). The closed forms
/// everywhere left c3 36 roundings off at z = 0.11 (1 - c1 ~ z/6); quartering everywhere, 555 at z = -109
/// (each quadrupling of a cosh compounds its rounding). Measured against long double over |z| <= 400:
/// c3 within 9 roundings.
inline constexpr double kStumpffClosedFrom = 1.0;

/// Stumpff functions c0..c3 of z (Danby eq. 6.9.x); for 0.1 <= |z| < 1 by quartering z, the series and
///   c0(4z) = 2 c0^2 - 1,  c1(4z) = c0 c1,  c2(4z) = c1^2 / 2,  c3(4z) = (c2 + c0 c3) / 4.
template <class T>
void stumpff(T z, T c[4]) {
  if (std::abs(z) >= T(kStumpffClosedFrom)) {
    const T q = std::sqrt(std::abs(z));
    c[0] = z > 0 ? std::cos(q) : std::cosh(q);
    c[1] = (z > 0 ? std::sin(q) : std::sinh(q)) / q;
    c[2] = (T(1) - c[0]) / z;
    c[3] = (T(1) - c[1]) / z;
    return;
  }
  int quarterings = 0;
  for (; std::abs(z) >= T(kStumpffSeriesBelow); ++quarterings) z /= 4;
  for (int n = 0; n < 4; ++n) {
    T term = 1;
    for (int j = 1; j <= n; ++j) term /= j;
    T sum = 0;
    for (int k = 0; k < 12; ++k) {
      sum += term;
      term *= -z / T((2 * k + n + 1) * (2 * k + n + 2));
    }
    c[n] = sum;
  }
  for (; quarterings > 0; --quarterings) {
    const T c0 = c[0], c1 = c[1], c2 = c[2], c3 = c[3];
    c[3] = (c2 + c0 * c3) / 4;
    c[2] = c1 * c1 / 2;
    c[1] = c0 * c1;
    c[0] = 2 * c0 * c0 - 1;
  }
}

/// The type a flow's final coefficients are taken in: x87's extended long double for a double flow where
/// long double is that (64-bit significand, in hardware), else T itself (a software binary128 would cost
/// more than it buys).
template <class T>
using KeplerWide = std::conditional_t<std::is_same_v<T, double> && std::numeric_limits<long double>::digits == 64, long double, T>;

/// The Lagrange coefficients of the flow over t (see the file comment), as increments.
template <class T>
struct KeplerCoefficients {
  T f_minus_1, g, fd, gd_minus_1;
};

/// The coefficients at the universal variable s of a flow with beta = 2 mu/r0 - v0.v0.
template <class T>
KeplerCoefficients<T> kepler_coefficients_at(T mu, T r0, T sigma0, T beta, T s) {
  // In KeplerWide<T>: taken in double, the Stumpff functions' roundings are the same function of the orbit's
  // phase every period and the energy of a repeated flow drifted one way (kep-y4's substeps on e = 0.5, 100
  // steps per period, 10^6 steps, 8 starts: |dE/E| 5.5e-13 on average, linear in the steps); in long double
  // and rounded once: 6.3e-14, the random walk of Brouwer's law, for 1 % more time (0.90 against 0.91 s CPU
  // for 9 x 10^5 flows, medians of 5). The search for s stays in T: any s gives a flow (f gd - fd g = 1).
  using W = KeplerWide<T>;
  W c[4];
  const W S = s;
  stumpff<W>(W(beta) * S * S, c);
  const W G1 = S * c[1], G2 = S * S * c[2];
  const W r = W(r0) * c[0] + W(sigma0) * G1 + W(mu) * G2;
  // g from s itself (t(s) - mu G3), not t - mu G3: s solves t(s) = t to a few roundings, and g taken from
  // t with f, fd, gd from s broke f gd - fd g = 1 by that much each step, one way (kep-y4, h = 1 on a bound
  // orbit, 300 steps: the energy drifted 1.0e-14, the state 2.0e-11 off the Kepler orbit at t = 300; now
  // +-3e-15 either way, 1.7e-12).
  return {T(-W(mu) * G2 / W(r0)), T(W(r0) * G1 + W(sigma0) * G2), T(-W(mu) * G1 / (W(r0) * r)), T(-W(mu) * G2 / r)};
}

/// The universal variable s of a flow over t > 0 from a state at distance r0 = |X0| with sigma0 = X0.v0 and
/// v0sq = v0.v0: t(s) = t to a few roundings.
template <class T>
T kepler_universal_variable(T mu, T r0, T sigma0, T v0sq, T t) {
  const T beta = T(2) * mu / r0 - v0sq;  // -2 x energy per unit mass
  T g[4];
  auto G = [&](T s) {
    T c[4];
    stumpff(beta * s * s, c);
    g[0] = c[0];
    g[1] = s * c[1];
    g[2] = s * s * c[2];
    g[3] = s * s * s * c[3];
  };
  auto tof = [&](T s) {
    G(s);
    return r0 * g[1] + sigma0 * g[2] + mu * g[3];
  };
  // Start from a lower bound, s >= t/(r0 + v_max t) with v_max^2 = |v0|^2 + 2|mu|/r0 (r grows at
  // most that fast), and double: a first guess like t/r0 overshoots by orders of magnitude when the
  // start is near the centre, and cosh of the overshoot overflows.
  const T v_max = std::sqrt(v0sq + T(2) * std::abs(mu) / r0);
  T lo = 0, hi = t / (r0 + v_max * t);
  while (tof(hi) < t) {
    lo = hi;
    hi *= T(2);
    if (!(hi < T(1e6))) throw std::runtime_error("kepler_flow: no bracket for the universal variable");
  }
  // Newton on t(s), kept inside the bracket (bisection where it would leave it).
  const T eps = T(4) * std::numeric_limits<T>::epsilon();
  T s = T(0.5) * (lo + hi);
  for (int it = 0; it < 400; ++it) {
    const T f = tof(s) - t;
    const T r = r0 * g[0] + sigma0 * g[1] + mu * g[2];
    if (f > 0) {
      hi = s;
    } else {
      lo = s;
    }
    T next = s - f / r;
    if (!(next > lo && next < hi)) next = T(0.5) * (lo + hi);
    if (std::abs(next - s) <= eps * std::abs(s) || hi - lo <= eps * hi) {
      s = next;
      break;
    }
    s = next;
  }
  return s;
}

/// Flow over t > 0 from a state at distance r0 = |X0| with sigma0 = X0.v0 and v0sq = v0.v0.
template <class T>
KeplerCoefficients<T> kepler_flow(T mu, T r0, T sigma0, T v0sq, T t) {
  const T s = kepler_universal_variable(mu, r0, sigma0, v0sq, t);
  return kepler_coefficients_at(mu, r0, sigma0, T(2) * mu / r0 - v0sq, s);
}

/// The same flow of a double state whose r0, sigma0 and v0sq were taken in KeplerWide<double> (from a state
/// held as a compensated pair, kepler_split.hpp): s is searched in double, and the coefficients, taken at s
/// from the wide values, are returned wide, so that the caller forms the increments there and rounds them once.
/// Any s gives a flow; the wide values make it the flow of the state the pair holds, not of its rounding.
inline KeplerCoefficients<KeplerWide<double>> kepler_flow_wide(double mu, KeplerWide<double> r0, KeplerWide<double> sigma0,
                                                               KeplerWide<double> v0sq, double t) {
  using W = KeplerWide<double>;
  const double s = kepler_universal_variable<double>(mu, double(r0), double(sigma0), double(v0sq), t);
  return kepler_coefficients_at<W>(W(mu), r0, sigma0, W(2) * W(mu) / r0 - v0sq, W(s));
}

}  // namespace bodypoint
