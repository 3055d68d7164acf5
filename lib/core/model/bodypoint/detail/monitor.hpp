// bodypoint: the first integrals over a force field (field.hpp) and the monitor that tracks their
// deviations along a run (docs/physics.md "First integrals"); invariants.hpp has the integrals a
// program outside the tree uses. Internal (not installed).
#pragma once

#include "bodypoint/field.hpp"
#include "bodypoint/invariant_stats.hpp"
#include "bodypoint/invariants.hpp"
#include "bodypoint/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace bodypoint {

template <class Field>
double energy(const BodyPoint& p, const Field& f, const State& s) {
  return kinetic_energy(p, s) + f.potential(s.R);
}

/// A start whose energy cancels to less than this fraction of its terms (near-parabolic: T0 ~ -U0) has
/// an E0 that carries the terms' rounding; its deviations are measured against this fraction of the
/// terms instead of |E0| (ks, exact in E, reported "energy error 7" for E0 ~ 0).
inline constexpr double kEnergyCancellation = 1e-6;

/// The scale a deviation of the energy from E0 = energy(s0) is measured against: |E0|, or
/// kEnergyCancellation (T0 + |U0|) where that is larger (docs/physics.md, First integrals).
template <class Field>
double energy_scale(const BodyPoint& p, const Field& f, const State& s0) {
  const double E0 = energy(p, f, s0);
  return std::max(std::abs(E0), kEnergyCancellation * (kinetic_energy(p, s0) + std::abs(f.potential(s0.R))));
}

/// Reference point about which K2Q is conserved, or nothing when the field has several centres.
inline std::optional<Vec3> angular_momentum_point(const OriginCentre&) { return Vec3::Zero(); }
inline std::optional<Vec3> angular_momentum_point(const CentreList& f) {
  if (f.single()) return f.reference_point();
  return std::nullopt;
}

/// |x - x0| / |x0| (|x - x0| where x0 = 0).
inline double relative_deviation(double x, double x0) {
  const double scale = std::abs(x0);
  return scale > 0.0 ? std::abs(x - x0) / scale : std::abs(x - x0);
}

/// Tracks the deviations of every integral the field has; one call per observed state, `step` for
/// the state that ends a step (it also measures the step's resolution), `update` for any other.
template <class Field>
class InvariantMonitor {
 public:
  InvariantMonitor(const BodyPoint& p, const Field& f, const State& s0)
      : p_(p), f_(f), c_(angular_momentum_point(f)), spin_rate_per_K1_(std::abs(p.B) * (1.0 / p.D())),
        prev_R_(s0.R) {
    E0_ = energy(p_, f_, s0);
    E_scale_ = energy_scale(p_, f_, s0);
    K2sq0_ = proper_momentum_sq(p_, s0);
    if (c_) K2Q0_ = total_angular_momentum(p_, s0, *c_);
    stats_.has_K2Q = c_.has_value();
    stats_.r0_attracting = stats_.min_r_attracting = f_.nearest_attracting(s0.R);
  }

  void update(const State& s) {
    last_rel_dE_ = E_scale_ > 0.0 ? std::abs(energy(p_, f_, s) - E0_) / E_scale_ : std::abs(energy(p_, f_, s) - E0_);
    stats_.max_rel_dE = max_keeping_nan(stats_.max_rel_dE, last_rel_dE_);
    last_rel_dK2sq_ = relative_deviation(proper_momentum_sq(p_, s), K2sq0_);
    stats_.max_rel_dK2sq = max_keeping_nan(stats_.max_rel_dK2sq, last_rel_dK2sq_);
    if (c_) {
      last_abs_dK2Q_ = (total_angular_momentum(p_, s, *c_) - K2Q0_).norm();
      stats_.max_abs_dK2Q = max_keeping_nan(stats_.max_abs_dK2Q, last_abs_dK2Q_);
    }
    stats_.min_r_attracting = std::min(stats_.min_r_attracting, f_.nearest_attracting(s.R));
  }

  /// The state s that ends a step of physical length dt: update(s) and the step's spin and orbital
  /// angles (the batch monitor, batch_w.cpp, does the same arithmetic).
  void step(const State& s, double dt) {
    update(s);
    if (spin_rate_per_K1_ > 0.0) {
      const double angle = spin_rate_per_K1_ * (p_.m * s.v + p_.B * s.w).norm() * dt;
      stats_.max_spin_angle = max_keeping_nan(stats_.max_spin_angle, angle);
    }
    stats_.min_turn_cos = std::min(stats_.min_turn_cos, f_.min_turn_cos(prev_R_, s.R));
    prev_R_ = s.R;
  }

  /// max that propagates NaN: std::max(x, NaN) is x, which would report a run full of NaN as clean.
  static double max_keeping_nan(double so_far, double x) {
    if (std::isnan(so_far) || std::isnan(x)) return std::numeric_limits<double>::quiet_NaN();
    return std::max(so_far, x);
  }

  [[nodiscard]] const InvariantStats& stats() const { return stats_; }
  [[nodiscard]] double last_rel_dE() const { return last_rel_dE_; }
  [[nodiscard]] double last_rel_dK2sq() const { return last_rel_dK2sq_; }
  [[nodiscard]] double last_abs_dK2Q() const { return last_abs_dK2Q_; }
  [[nodiscard]] double E0() const { return E0_; }

 private:
  BodyPoint p_;
  const Field& f_;
  std::optional<Vec3> c_;
  double E0_ = 0.0, E_scale_ = 0.0, K2sq0_ = 0.0;
  double spin_rate_per_K1_;  ///< |B|/D: Omega_so = |B| |K1|/D
  Vec3 prev_R_;              ///< where the last step started
  Vec3 K2Q0_ = Vec3::Zero();
  InvariantStats stats_;
  double last_rel_dE_ = 0.0, last_rel_dK2sq_ = 0.0, last_abs_dK2Q_ = 0.0;
};

}  // namespace bodypoint
