// bodypoint: Kustaanheimo-Stiefel regularisation of a material point (B = 0) in one centre's field.
//
// E. Stiefel, G. Scheifele, Linear and Regular Celestial Mechanics (Springer 1971), ch. 9-10:
// with R - c = L(u) u for u in R^4, r = |u|^2, and the fictitious time s, dt/ds = r, the Kepler
// motion d^2R/dt^2 = -mu R/r^3 (mu = A/m, either sign) becomes the linear oscillator
//   u'' = (h/2) u,      h = |v|^2/2 - mu/r  (energy per unit mass, constant),
// and the physical time obeys r'' = 2 h r + mu. Both are solved exactly with Stumpff functions
// c_n(z) (J. M. A. Danby, Fundamentals of Celestial Mechanics, 2nd ed. 1988, sec. 6.9):
//   u(s)  = u0 c0(z) + u0' s c1(z),            u'(s) = u0 (h/2) s c1(z) + u0' c0(z),   z = -(h/2) s^2,
//   t(s)  = r0 s c1(Z) + r0' s^2 c2(Z) + mu s^3 c3(Z),   Z = -2 h s^2,  r0' = 2 u0.u0'.
// A step of any ds is exact up to rounding, so the scheme follows the Rutherford (A < 0) or Kepler
// (A > 0) conic to round-off, through a head-on collision with an attracting centre as well.
// The spin w of a material point is constant and carried along.
#pragma once

#include "bodypoint/model.hpp"

#include <Eigen/Core>

#include <cmath>
#include <stdexcept>

namespace bodypoint::adaptive {

using Vec4 = Eigen::Vector4d;

/// Stumpff functions c0..c3 at z.
inline void stumpff(double z, double c[4]) {
  if (std::abs(z) < 0.1) {
    for (int n = 0; n < 4; ++n) {
      double term = 1.0, sum = 0.0;
      for (int j = 1; j <= n; ++j) term /= j;
      for (int k = 0; k < 12; ++k) {
        sum += term;
        term *= -z / ((2 * k + n + 1) * (2 * k + n + 2));
      }
      c[n] = sum;
    }
    return;
  }
  if (z > 0) {
    const double q = std::sqrt(z);
    c[0] = std::cos(q);
    c[1] = std::sin(q) / q;
  } else {
    const double q = std::sqrt(-z);
    c[0] = std::cosh(q);
    c[1] = std::sinh(q) / q;
  }
  c[2] = (1.0 - c[0]) / z;
  c[3] = (1.0 - c[1]) / z;
}

/// The KS state of a material point about centre c.
class KsMotion {
 public:
  KsMotion(const BodyPoint& p, const Centre& centre, const State& s0) : c_(centre.c), w_(s0.w) {
    mu_ = centre.A / p.m;
    const Vec3 x = s0.R - c_;
    const double r = x.norm();
    if (!(r > 0.0)) throw Error("ks: the body starts on the centre");
    // Inverse KS map, the branch that avoids cancellation (Stiefel-Scheifele sec. 9.3).
    if (x.x() >= 0.0) {
      u_[0] = std::sqrt(0.5 * (r + x.x()));
      u_[3] = 0.0;
      u_[1] = x.y() / (2.0 * u_[0]);
      u_[2] = x.z() / (2.0 * u_[0]);
    } else {
      u_[1] = std::sqrt(0.5 * (r - x.x()));
      u_[2] = 0.0;
      u_[0] = x.y() / (2.0 * u_[1]);
      u_[3] = x.z() / (2.0 * u_[1]);
    }
    up_ = 0.5 * Lt(u_) * s0.v;  // u' = (1/2) L(u)^T v
    h_ = 0.5 * s0.v.squaredNorm() - mu_ / r;
  }

  /// Advances by the fictitious time ds; returns the physical time elapsed.
  double step(double ds) {
    double c[4];
    stumpff(-0.5 * h_ * ds * ds, c);
    const Vec4 u = u_ * c[0] + up_ * (ds * c[1]);
    const Vec4 up = u_ * (0.5 * h_ * ds * c[1]) + up_ * c[0];
    const double dt = elapsed(ds);
    u_ = u;
    up_ = up;
    return dt;
  }

  /// Physical time that a fictitious step ds would take from the current state.
  [[nodiscard]] double elapsed(double ds) const {
    double c[4];
    stumpff(-2.0 * h_ * ds * ds, c);
    const double r0 = u_.squaredNorm(), rp0 = 2.0 * u_.dot(up_);
    return r0 * ds * c[1] + rp0 * ds * ds * c[2] + mu_ * ds * ds * ds * c[3];
  }

  /// The fictitious step that takes exactly the physical time dt (dt/ds = r > 0: bisection-Newton).
  [[nodiscard]] double step_for_time(double dt) const {
    double lo = 0.0, hi = dt / std::max(u_.squaredNorm(), 1e-300);
    for (int k = 0; elapsed(hi) < dt; ++k) {
      lo = hi;
      hi *= 2.0;
      if (k > 200) throw Error("ks: cannot bracket the final fictitious step");
    }
    double s = 0.5 * (lo + hi);
    for (int it = 0; it < 200; ++it) {
      const double f = elapsed(s) - dt;
      if (f > 0) hi = s; else lo = s;
      // dt/ds at s: r(s) = |u(s)|^2
      double c[4];
      stumpff(-0.5 * h_ * s * s, c);
      const double r = (u_ * c[0] + up_ * (s * c[1])).squaredNorm();
      double next = s - f / r;
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::abs(next - s) <= 4e-16 * s) return next;
      s = next;
    }
    return s;
  }

  [[nodiscard]] State state() const {
    const double r = u_.squaredNorm();
    State s;
    s.R = c_ + Lu(u_);
    s.v = (2.0 / r) * (L(u_) * up_);
    s.w = w_;
    return s;
  }

 private:
  using Mat34 = Eigen::Matrix<double, 3, 4>;
  static Mat34 L(const Vec4& u) {
    Mat34 m;
    m << u[0], -u[1], -u[2], u[3],
         u[1], u[0], -u[3], -u[2],
         u[2], u[3], u[0], u[1];
    return m;
  }
  static Eigen::Matrix<double, 4, 3> Lt(const Vec4& u) { return L(u).transpose(); }
  static Vec3 Lu(const Vec4& u) { return L(u) * u; }

  Vec3 c_, w_;
  Vec4 u_ = Vec4::Zero(), up_ = Vec4::Zero();
  double mu_ = 0.0, h_ = 0.0;
};

}  // namespace bodypoint::adaptive
