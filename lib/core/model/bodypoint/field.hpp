// bodypoint: Coulomb fields.
//
// F(R) = -A (R - c)/|R - c|^3,  Pi(R) = -A/|R - c|  (docs/physics.md "Model"; thesis eq. 1.2).
// Forces and potentials of several centres add. Two field types let a step loop pay only for
// what the scene holds: `OriginCentre` (one centre at the origin, no centre loop, the total
// angular momentum K2Q about it is conserved) and `CentreList` (any number, anywhere).
// The choice is made once, outside the step loop, by `visit_field`.
#pragma once

#include "bodypoint/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace bodypoint {

/// Cosine of the angle between a and b (1 when either is zero: no direction to turn).
inline double turn_cos(const Vec3& a, const Vec3& b) {
  const double q = a.squaredNorm() * b.squaredNorm();
  return q > 0.0 ? a.dot(b) / std::sqrt(q) : 1.0;
}

struct OriginCentre {
  double A = 0.0;
  /// K2Q = R x K1 + K2 is a first integral only for a single centre (taken as the origin).
  static constexpr bool has_angular_momentum = true;

  [[nodiscard]] Vec3 force(const Vec3& R) const {
    const double r2 = R.squaredNorm();
    const double inv_r = 1.0 / std::sqrt(r2);
    return (-A * inv_r * inv_r * inv_r) * R;
  }
  [[nodiscard]] double potential(const Vec3& R) const { return -A / R.norm(); }
  [[nodiscard]] Vec3 reference_point() const { return Vec3::Zero(); }
  /// Distance to the nearest attracting centre (infinite when none attracts).
  [[nodiscard]] double nearest_attracting(const Vec3& R) const {
    return A > 0.0 ? R.norm() : std::numeric_limits<double>::infinity();
  }
  /// Cosine of the angle through which the direction to the centre turned from `from` to `to`
  /// (1 when the centre exerts no force).
  [[nodiscard]] double min_turn_cos(const Vec3& from, const Vec3& to) const {
    return A != 0.0 ? turn_cos(from, to) : 1.0;
  }

  /// F and Pi in one pass (one force evaluation).
  void force_potential(const Vec3& R, Vec3& F, double& P) const {
    const double inv_r = 1.0 / std::sqrt(R.squaredNorm());
    F = (-A * inv_r * inv_r * inv_r) * R;
    P = -A * inv_r;
  }
  /// F, Omega = |A|/r and grad Omega = -|A| R/r^3 in one pass (the TTL's time-step function).
  void force_omega(const Vec3& R, Vec3& F, double& Omega, Vec3& grad) const {
    const double inv_r = 1.0 / std::sqrt(R.squaredNorm());
    const double inv_r3 = inv_r * inv_r * inv_r;
    F = (-A * inv_r3) * R;
    Omega = std::abs(A) * inv_r;
    grad = (-std::abs(A) * inv_r3) * R;
  }
};

/// |F|/(|A| r) for centre k at distance 1/inv_r: 1/r^3 (Coulomb), or 1/r^1.5 for the thesis code's law
/// (model.hpp, ForceLaw). Scenes with a non-Coulomb centre always take CentreList.
inline double inverse_cube(const Centre& k, double inv_r) {
  return k.law == ForceLaw::coulomb ? inv_r * inv_r * inv_r : inv_r * std::sqrt(inv_r);
}

struct CentreList {
  std::vector<Centre> centres;
  /// With one centre at c, K2Q = (R - c) x K1 + K2 is still conserved.
  static constexpr bool has_angular_momentum = false;

  [[nodiscard]] Vec3 force(const Vec3& R) const {
    Vec3 F = Vec3::Zero();
    for (const Centre& k : centres) {
      const Vec3 d = R - k.c;
      const double inv_r = 1.0 / std::sqrt(d.squaredNorm());
      F -= (k.A * inverse_cube(k, inv_r)) * d;
    }
    return F;
  }
  [[nodiscard]] double potential(const Vec3& R) const {
    double P = 0.0;
    for (const Centre& k : centres) P -= k.A / (R - k.c).norm();
    return P;
  }
  [[nodiscard]] double nearest_attracting(const Vec3& R) const {
    double r = std::numeric_limits<double>::infinity();
    for (const Centre& k : centres)
      if (k.A > 0.0) r = std::min(r, (R - k.c).norm());
    return r;
  }
  /// The smallest cosine of the angles through which the directions to the centres (A != 0) turned.
  [[nodiscard]] double min_turn_cos(const Vec3& from, const Vec3& to) const {
    double c = 1.0;
    for (const Centre& k : centres)
      if (k.A != 0.0) c = std::min(c, turn_cos(from - k.c, to - k.c));
    return c;
  }
  void force_potential(const Vec3& R, Vec3& F, double& P) const {
    F.setZero();
    P = 0.0;
    for (const Centre& k : centres) {
      const Vec3 d = R - k.c;
      const double inv_r = 1.0 / std::sqrt(d.squaredNorm());
      F -= (k.A * inverse_cube(k, inv_r)) * d;
      P -= k.A * inv_r;
    }
  }
  void force_omega(const Vec3& R, Vec3& F, double& Omega, Vec3& grad) const {
    F.setZero();
    grad.setZero();
    Omega = 0.0;
    for (const Centre& k : centres) {
      const Vec3 d = R - k.c;
      const double inv_r = 1.0 / std::sqrt(d.squaredNorm());
      const double inv_r3 = inv_r * inv_r * inv_r;
      F -= (k.A * inverse_cube(k, inv_r)) * d;
      Omega += std::abs(k.A) * inv_r;
      grad -= (std::abs(k.A) * inv_r3) * d;
    }
  }
  [[nodiscard]] bool single() const { return centres.size() == 1; }
  [[nodiscard]] Vec3 reference_point() const { return centres.front().c; }
};

/// True when every centre repels (A < 0), so that Pi > 0 everywhere.
inline bool all_repulsive(const std::vector<Centre>& centres) {
  for (const Centre& k : centres)
    if (!(k.A < 0.0)) return false;
  return true;
}

/// Calls f(OriginCentre) for one Coulomb centre at the origin, f(CentreList) otherwise.
template <class F>
decltype(auto) visit_field(const std::vector<Centre>& centres, F&& f) {
  if (centres.size() == 1 && centres.front().c.isZero(0.0) && centres.front().law == ForceLaw::coulomb)
    return f(OriginCentre{centres.front().A});
  return f(CentreList{centres});
}

}  // namespace bodypoint
