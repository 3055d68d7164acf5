// bodypoint: where a search starts (search.hpp): its first, coarse step, and a step as a way of advancing time.
#include "search.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/field.hpp"
#include "bodypoint/detail/run_parts.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bodypoint::adaptive::detail {
namespace {

/// far-ip's first step turns the spin by at most this many turns (docs/measurements.md, "Tuned constants").
constexpr double kFarFieldTurns = 1.0;

double speed_of(const Body& b) { return b.s0.v.norm(); }

double strength(const std::vector<Centre>& centres) {
  double s = 0.0;
  for (const Centre& c : centres) s += std::abs(c.A);
  return s;
}

}  // namespace

double spin_orbit_period(const Body& b) {
  const double rate = std::abs(b.p.B) * to_momenta(b.p, b.s0).K1.norm() / b.p.D();
  return rate > 0.0 ? 2.0 * M_PI / rate : std::numeric_limits<double>::infinity();
}

Advance step_advance(const MethodInfo& m, double h, double t_end, double dt_out) {
  if (is_time_transformed(m)) return FictitiousSteps{h, EndTime{t_end}, dt_out};
  const double n = steps_landing_on(t_end, h);
  if (!(n <= 1e12)) throw SearchLimit("tol: the step the search needs (" + std::to_string(h) + ") is too small");
  return FixedSteps{t_end / n, static_cast<long>(n), dt_out};
}

double initial_step(const MethodInfo& m, const Body& b, const std::vector<Centre>& centres, double t_end) {
  if (m.traits.search == SearchStrategy::exact_pair) {
    // KS fictitious time: one sub-step of the exact flow (sqrt(2 |h|) ds = 1, ks.hpp).
    const double mu = centres.front().A / b.p.m;
    const double h = 0.5 * b.s0.v.squaredNorm() - mu / (b.s0.R - centres.front().c).norm();
    return h != 0.0 ? 1.0 / std::sqrt(2.0 * std::abs(h)) : 1.0;
  }
  if (m.traits.search == SearchStrategy::field_pair) {
    // far-ip's step is set by the field's slow scale (far_field.hpp): the time the guiding centre takes to
    // cover its least distance to the nearest centre; a step too long for the field is refused and halved.
    const Helix helix = helix_of(b.p, to_momenta(b.p, b.s0));
    double r = std::numeric_limits<double>::infinity();
    for (const Centre& c : centres) r = std::min(r, path_distance(helix, c.c, t_end));
    const double v = helix.velocity.norm(), turn = spin_orbit_period(b);
    return std::min({t_end, v > 0.0 ? r / v : t_end, kFarFieldTurns * turn});
  }
  if (is_time_transformed(m)) {
    // dt = ds r/|A| near a centre advances the orbit by ds v/|A| radians: one radian per step.
    const double v = speed_of(b), a = strength(centres);
    return (v > 0.0 && a > 0.0) ? a / v : 0.1;
  }
  return std::min(t_end / 16.0, spin_orbit_period(b));
}

}  // namespace bodypoint::adaptive::detail
