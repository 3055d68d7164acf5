// bodypoint: first integrals and their deviation along a run (docs/physics.md "First integrals").
//
//   E    = 1/2 m v.v + B v.w + 1/2 J w.w + Pi(R)   (thesis eq. 4.1 with Erratum 2: B v.w, not B/2 v.w)
//   K2Q  = (R - c) x K1 + K2                       (eq. 1.6; a vector, only for a single centre c)
//   |K2|^2                                         (eq. 4.2)
//
// What a run tracks of them (the monitor, over the production force field) is internal:
// detail/monitor.hpp.
#pragma once

#include "bodypoint/model.hpp"

#include <vector>

namespace bodypoint {

/// The kinetic part of E.
inline double kinetic_energy(const BodyPoint& p, const State& s) {
  return 0.5 * p.m * s.v.squaredNorm() + p.B * s.v.dot(s.w) + 0.5 * p.J * s.w.squaredNorm();
}

/// E of a state in the field of the centres.
double energy(const BodyPoint& p, const std::vector<Centre>& centres, const State& s);

/// K2Q about the point c: (R - c) x K1 + K2 (conserved about a single centre at c).
inline Vec3 total_angular_momentum(const BodyPoint& p, const State& s, const Vec3& c) {
  const Momenta q = to_momenta(p, s);
  return (s.R - c).cross(q.K1) + q.K2;
}

/// |K2|^2 = |B v + J w|^2.
inline double proper_momentum_sq(const BodyPoint& p, const State& s) {
  return (p.B * s.v + p.J * s.w).squaredNorm();
}

}  // namespace bodypoint
