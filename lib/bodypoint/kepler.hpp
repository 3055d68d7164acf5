// bodypoint: the two-body flow d^2X/dt^2 = -mu X/|X|^3 over a time t, by the universal-variable form
// of Kepler's equation (J. M. A. Danby, Fundamentals of Celestial Mechanics, 2nd ed. 1988, sec. 6.9;
// Stumpff functions), valid for attraction (mu > 0) and repulsion (mu < 0) alike.
//
// With beta = 2 mu/r0 - v0.v0 and G_n(s) = s^n c_n(beta s^2), the universal variable s solves
//   t = r0 G1 + sigma0 G2 + mu G3,   sigma0 = X0.v0,   dt/ds = r(s) = r0 G0 + sigma0 G1 + mu G2 > 0,
// and X = f X0 + g v0, v = fd X0 + gd v0 with f = 1 - mu G2/r0, g = t - mu G3, fd = -mu G1/(r0 r),
// gd = 1 - mu G2/r. `kepler_flow` returns the increments f - 1, g, fd, gd - 1 (so that a caller adds
// X += (f - 1) X0 + g v0 without the cancellation of f X0 - X0 for short steps).
//
// One template serves the long-double oracle (reference.hpp) and the Kepler split (kepler_split.hpp).
#pragma once

#include <cmath>
#include <limits>
#include <stdexcept>

namespace bodypoint {

/// Stumpff functions c0..c3 of z (Danby eq. 6.9.x).
template <class T>
void stumpff(T z, T c[4]) {
  if (std::abs(z) < T(0.1)) {
    // Series c_n(z) = sum (-z)^k/(2k+n)!: |z| < 0.1 and 12 terms leave a remainder below
    // 0.1^12/25! ~ 1e-37, far under long double's 1e-19.
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
    return;
  }
  if (z > 0) {
    const T s = std::sqrt(z);
    c[0] = std::cos(s);
    c[1] = std::sin(s) / s;
  } else {
    const T s = std::sqrt(-z);
    c[0] = std::cosh(s);
    c[1] = std::sinh(s) / s;
  }
  c[2] = (T(1) - c[0]) / z;
  c[3] = (T(1) - c[1]) / z;
}

/// The Lagrange coefficients of the flow over t (see the file comment), as increments.
template <class T>
struct KeplerCoefficients {
  T f_minus_1, g, fd, gd_minus_1;
};

/// Flow over t > 0 from a state at distance r0 = |X0| with sigma0 = X0.v0 and v0sq = v0.v0.
template <class T>
KeplerCoefficients<T> kepler_flow(T mu, T r0, T sigma0, T v0sq, T t) {
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
  G(s);
  const T r = r0 * g[0] + sigma0 * g[1] + mu * g[2];
  return {-mu * g[2] / r0, t - mu * g[3], -mu * g[1] / (r0 * r), -mu * g[2] / r};
}

}  // namespace bodypoint
