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

#include "bodypoint/kepler.hpp"
#include "bodypoint/model.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace bodypoint::adaptive {

using Vec4 = Eigen::Vector4d;

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
    q_ = oscillator_energy();
  }

  /// Advances by the fictitious time ds; returns the physical time elapsed. The flow is exact for any
  /// ds, but a long fictitious step makes the Stumpff functions of the time equation huge (cosh of
  /// sqrt(2 |h|) ds on a hyperbola) and the three terms of t(s) cancel: ds = 2.3 lost 1e-12..2e-9
  /// and ds = 8 overflowed at a pericentre. The step is therefore made of equal sub-steps with
  /// sqrt(2 |h|) ds_sub <= kMaxStumpffArgument, where no term exceeds a few times the sum.
  double step(double ds) {
    const int n = substeps(ds);
    const double sub = ds / n;
    double dt = 0.0;
    for (int i = 0; i < n; ++i) dt += substep(sub);
    return dt;
  }

  /// Physical time that a fictitious step ds would take from the current state.
  [[nodiscard]] double elapsed(double ds) const {
    KsMotion copy = *this;
    return copy.step(ds);
  }

  /// Advances by exactly the physical time dt > 0 (dt/ds = r > 0, so t(s) is increasing): whole
  /// sub-steps while they stay within dt, then the last fraction by a safeguarded Newton iteration on
  /// [0, one sub-step], where every Stumpff argument is bounded. Returns the fictitious time taken.
  double advance_time(double dt) {
    const double sub = max_substep();
    double s_total = 0.0, remaining = dt;
    for (long k = 0;; ++k) {
      const double one = time_equation(sub);
      if (!(one < remaining)) break;
      substep(sub);
      remaining -= one;
      s_total += sub;
      if (k > kMaxSubsteps) throw Error("ks: more than 1e9 sub-steps to reach the requested time");
    }
    double lo = 0.0, hi = std::isfinite(sub) ? sub : remaining / u_.squaredNorm();
    while (!(time_equation(hi) >= remaining)) {  // only when sub is unbounded (h = 0): widen
      lo = hi;
      hi *= 2.0;
      if (!std::isfinite(hi)) throw Error("ks: cannot bracket the final fictitious step");
    }
    double s = lo + (hi - lo) * std::clamp(remaining / time_equation(hi), 0.0, 1.0);
    for (int it = 0; it < 100; ++it) {
      const double f = time_equation(s) - remaining;
      if (f > 0) hi = s; else lo = s;
      double next = s - f / radius_after(s);  // dt/ds = r(s)
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::abs(next - s) <= 4e-16 * std::max(s, 1e-300) || hi - lo <= 4e-16 * hi) {
        s = next;
        break;
      }
      s = next;
    }
    substep(s);
    return s_total + s;
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

  /// sqrt(2 |h|) times a sub-step stays below this (see step()).
  static constexpr double kMaxStumpffArgument = 1.0;
  static constexpr long kMaxSubsteps = 1'000'000'000L;

  [[nodiscard]] double max_substep() const {
    const double rate = std::sqrt(2.0 * std::abs(h_));
    return rate > 0.0 ? kMaxStumpffArgument / rate : std::numeric_limits<double>::infinity();
  }
  [[nodiscard]] int substeps(double ds) const {
    const double n = std::ceil(std::abs(ds) / max_substep());
    if (!(n <= 1e9)) throw Error("ks: the fictitious step needs more than 1e9 sub-steps; reduce the fictitious step ds");
    return std::max(1, static_cast<int>(n));
  }

  /// One exact sub-step of fictitious length ds (Stumpff arguments bounded); returns its dt.
  double substep(double ds) {
    double c[4];
    stumpff(-0.5 * h_ * ds * ds, c);
    const Vec4 u = u_ * c[0] + up_ * (ds * c[1]);
    const Vec4 up = u_ * (0.5 * h_ * ds * c[1]) + up_ * c[0];
    const double dt = time_equation(ds);
    u_ = u;
    up_ = up;
    // Back onto the oscillator's energy of the start, on a bound orbit (see oscillator_energy).
    const double q = oscillator_energy();
    if (h_ < 0.0 && q_ > 0.0 && q > 0.0) {
      const double scale = std::sqrt(q_ / q);
      u_ *= scale;
      up_ *= scale;
    }
    return dt;
  }
  /// t(ds) from the current state (Danby sec. 6.9), for ds no longer than a sub-step.
  [[nodiscard]] double time_equation(double ds) const {
    double c[4];
    stumpff(-2.0 * h_ * ds * ds, c);
    const double r0 = u_.squaredNorm(), rp0 = 2.0 * u_.dot(up_);
    return r0 * ds * c[1] + rp0 * ds * ds * c[2] + mu_ * ds * ds * ds * c[3];
  }
  /// r = |u|^2 after a fictitious time ds.
  [[nodiscard]] double radius_after(double ds) const {
    double c[4];
    stumpff(-0.5 * h_ * ds * ds, c);
    return (u_ * c[0] + up_ * (ds * c[1])).squaredNorm();
  }

  /// |u'|^2 - (h/2)|u|^2, which the flow conserves (it is mu/2: |u'|^2 = r|v|^2/4). A sub-step's matrix
  /// [[c0, ds c1], [(h/2) ds c1, c0]] has determinant 1 only up to rounding, and with a fixed ds the same
  /// rounding every sub-step: the oscillator's amplitude grew one way, the energy with it and the phase
  /// as the square of the steps (ds = 0.01 on a bound orbit to t = 300: 7e-12 in energy, 2.9e-10 in the
  /// state). On a bound orbit (h < 0: both terms positive, q formed to a rounding) each sub-step scales u
  /// and u' back to the start's value (1.5e-13 in the state). Unbound (h >= 0) q is the difference of
  /// terms far larger than it (r = 5000 from L = 4000: 2.5e4 each for q = -1), its rounding 1e4 times
  /// the drift it would correct (the time delay of such a pass moved by 1.9e-8); a pass is not long
  /// enough for the drift to matter there.
  [[nodiscard]] double oscillator_energy() const { return up_.squaredNorm() - 0.5 * h_ * u_.squaredNorm(); }

  Vec3 c_, w_;
  double q_ = 0.0;
  Vec4 u_ = Vec4::Zero(), up_ = Vec4::Zero();
  double mu_ = 0.0, h_ = 0.0;
};

}  // namespace bodypoint::adaptive
