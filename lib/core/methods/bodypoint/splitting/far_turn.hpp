// bodypoint: a far-field leg whose steps hold many turns of the spin, its cost growing like log L.
//
// docs/physics.md, "The far field by one turn a step". Far from every centre a spinning body's fast
// motion is the exact kinetic drift (K2 turns about K1 with period T = 2 pi D/(B |K1|), R follows the
// helix about its guiding centre) and the force changes on the slow scale r/|v|, a few hundred turns.
// A splitting's kick at one point of the helix resonates with the spin once a step holds more than
// about 2 rad of it (docs/measurements.md, "Limits, measured"). Here a kick of weight tau is one turn
// of the exact flows instead: M kicks of weight tau/M at the centres of M equal arcs of a full turn,
// joined by exact drifts, with a drift of -T/2 before and after, so that the turn adds no time:
//
//   E(tau) = D(T/2M - T/2) K(tau/M) D(T/M) K(tau/M) ... D(T/M) K(tau/M) D(T/2M - T/2).
//
// To first order in the force E(tau) adds tau times the force averaged over the helix's phases (the M
// points integrate its harmonics below M exactly; the k-th is (rho/r)^k of it), and every kick holds
// R and moves K1, so what a kick does to the helix's axis (the guiding centre's drift) is the exact
// splitting's, summed over the turn. Any splitting table with E for its kicks integrates the slow,
// phase-averaged motion at the table's order in the step (stroboscopic averaging: Calvo, Chartier,
// Murua and Sanz-Serna, Appl. Numer. Math. 61, 2011), so the step is set by r/|v| and not by the spin.
//
// The averaged motion differs from the real one by the quiver, the oscillating part of the motion
// integrated over a turn: of size |F| rho/(|K1| Omega) in R and rho |grad F|/Omega in K1. A leg moves
// the real start onto the averaged motion and its end back by a turn whose kicks have zero total weight,
// w_j = kQuiverShare s_j/M for the arc centres s_j in (-T/2, T/2), which adds that share of the quiver;
// the share is measured, not derived (kQuiverShare).
#pragma once

#include "bodypoint/field.hpp"
#include "bodypoint/model.hpp"
#include "bodypoint/splitting/composition.hpp"
#include "bodypoint/splitting/lie_poisson.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace bodypoint::splitting {

/// Phases a turn samples: the force's M-th harmonic along the helix, (rho/r)^M of it, is the first it
/// does not integrate (1e-10 at rho/r = 3e-3: table 3.1's helix at r = 377). 3, 4 and 6 gave the same
/// error on table 3.1 from L = 3200 to r = 377 (bench/far_turn.cpp).
inline constexpr int kTurnPoints = 4;
/// The share of the quiver turn (file comment) that moves a real state onto the averaged motion. Measured
/// on table 3.1 (B = 0.3, 0.7, 0.9) from L = 3200 to r = 400: the velocity's error against the exact
/// splitting fell from 4.4e-6 to 1.7e-8 at 0.5, 4.4e-7 at 0.45 and 0.55 (bench/far_turn.cpp); the
/// first-order theory of a centred turn gives 1, which doubles the error instead.
inline constexpr double kQuiverShare = 0.5;
/// A leg refuses to run where the spin turns fewer than this many times while the body crosses its
/// distance to the nearest centre (T |v| > r/kMinTurns): the force is no longer nearly constant over a
/// turn (B = 0.01 on table 3.1, 0.6 turns at r = 400, erred 9e-4). Table 3.1 turns 22 times at r = 200.
inline constexpr double kMinTurns = 10.0;

/// The distance to the nearest centre (the slow scale's length).
inline double nearest_centre(const OriginCentre&, const Vec3& R) { return R.norm(); }
inline double nearest_centre(const CentreList& f, const Vec3& R) {
  double r = std::numeric_limits<double>::infinity();
  for (const Centre& c : f.centres) r = std::min(r, (R - c.c).norm());
  return r;
}

/// The exact drift, and for a kick one turn of the exact flows (file comment). Needs B != 0.
template <class Field>
struct FarTurnKernel {
  using state_type = LieState;
  static constexpr bool mergeable = false;  // a kick is a turn: consecutive kicks do not merge

  LiePoissonKernel<Field, true> lp;
  double quiver_share = kQuiverShare;  ///< bench/far_turn.cpp varies it

  FarTurnKernel(const BodyPoint& p, Field f) : lp(p, std::move(f)) {}

  [[nodiscard]] LieState initial_state(const State& s0) const { return lp.initial_state(s0); }
  [[nodiscard]] State to_physical(const LieState& x) const { return lp.to_physical(x); }
  void begin_step(LieState&) const {}
  [[nodiscard]] long evals() const { return lp.evals; }

  /// The spin's period 2 pi D/(B |K1|).
  [[nodiscard]] double period(const LieState& x) const {
    return 2.0 * std::numbers::pi * lp.p.D() / (std::abs(lp.p.B) * x.K1.norm());
  }
  void drift(LieState& x, double tau) const { lp.drift(x, tau); }
  /// E(tau): tau/M at each of the M arc centres of one turn.
  void kick(LieState& x, double tau) {
    std::array<double, kTurnPoints> w{};
    w.fill(tau / kTurnPoints);
    turn(x, w);
  }
  /// Moves a real state onto the averaged motion (to = averaged) or back (to = real).
  enum class Onto { averaged, real };
  void quiver(LieState& x, Onto to) {
    const double T = period(x);
    const double sign = to == Onto::real ? -quiver_share : quiver_share;
    std::array<double, kTurnPoints> w{};
    for (int j = 0; j < kTurnPoints; ++j) w[j] = sign * ((j + 0.5) * T / kTurnPoints - 0.5 * T) / kTurnPoints;
    turn(x, w);
  }

 private:
  /// Kicks of weights w at the arc centres of one turn about the current time; no time added.
  void turn(LieState& x, const std::array<double, kTurnPoints>& w) {
    const double T = period(x);
    lp.drift(x, T / (2 * kTurnPoints) - 0.5 * T);
    for (int j = 0; j < kTurnPoints; ++j) {
      lp.kick(x, w[j]);
      lp.drift(x, j + 1 < kTurnPoints ? T / kTurnPoints : T / (2 * kTurnPoints) - 0.5 * T);
    }
  }
};

/// Where a leg ends: once the guiding centre G = R + K1 x K2/|K1|^2 is within `r` of `about` (coming
/// in), or `beyond` it (going out). The last steps are shortened to land there (kLandSlack).
struct LegStop {
  Vec3 about = Vec3::Zero();
  double r = 0.0;
  bool beyond = false;
};
/// A leg has reached its stop within this share of the distance. A landing step aims at the stop by
/// the guiding centre's rate and misses it by what the force bends the path over the step (1e-4 at
/// r = 1600 on table 3.1, outwards: 1e-7 of it); the next one, forwards or back, lands within rounding.
inline constexpr double kLandSlack = 1e-11;
/// Landing steps before a leg gives up (two suffice where the force is weak enough for a leg).
inline constexpr int kMaxLandings = 6;

/// What a leg did.
struct FarLeg {
  double t = 0.0;
  long steps = 0;
  bool reached = false;  ///< ended at its stop (LegStop), not at t_span
  /// Why the leg stopped short, in one line (the state is then where it stopped, and real); empty when it
  /// did not: a turn too long for the slow scale (kMinTurns), a guiding centre that moves away from its
  /// stop, no landing within kMaxLandings steps.
  std::string refused;
  /// The size of the two quiver corrections, max(|dR|/|R|, |dv|/|v|) each, summed: what a leg's model
  /// error is measured against (docs/measurements.md, "An encounter at infinity").
  double quiver = 0.0;
  /// The end state before its quiver correction (on the averaged motion).
  State averaged_end;
};

namespace detail {
/// The guiding centre's distance from `about` and its rate of change (the guiding centre moves at
/// (J |K1| - B K2.u)/D along u = K1/|K1| during a drift).
template <class Field>
void guiding_distance(const FarTurnKernel<Field>& k, const LieState& x, const Vec3& about, double& g, double& rate) {
  const Vec3 R = x.R - x.R_err, K1 = x.K1 - x.K1_err;
  const double K1sq = K1.squaredNorm(), K1n = std::sqrt(K1sq);
  const Vec3 d = R + K1.cross(x.K2) / K1sq - about;
  const Vec3 u = K1 / K1n;
  const double speed = (k.lp.p.J * K1n - k.lp.p.B * x.K2.dot(u)) / k.lp.p.D();
  g = d.norm();
  rate = speed * u.dot(d) / g;
}
}  // namespace detail

/// The far leg: the table's steps h = eta r/|v| (r: the nearest centre) with E for its kicks, from a
/// real state for the time t_span or until its stop, the state real again at its end. It stops short,
/// saying why (FarLeg::refused), where a turn is too long for the slow scale (kMinTurns), where the
/// guiding centre moves away from its stop (a leg coming in that the field turns back before it, one
/// going out that turns in), or where it cannot land.
template <const auto& Seq, class Field>
FarLeg far_leg(FarTurnKernel<Field>& k, LieState& x, double t_span, double eta, const LegStop& stop) {
  using Onto = typename FarTurnKernel<Field>::Onto;
  FarLeg leg;
  const auto corrected = [&](Onto to) {
    const State before = k.to_physical(x);
    k.quiver(x, to);
    leg.quiver += state_distance(k.to_physical(x), before);
  };
  corrected(Onto::averaged);
  for (int landings = 0; leg.t < t_span;) {
    double g = 0.0, rate = 0.0;
    detail::guiding_distance(k, x, stop.about, g, rate);
    if (std::abs(g - stop.r) <= kLandSlack * stop.r) {
      leg.reached = true;
      break;
    }
    const bool passed = stop.beyond ? g > stop.r : g < stop.r;
    const double r = nearest_centre(k.lp.field, x.R - x.R_err);
    const double v = k.to_physical(x).v.norm();
    if (!passed && (stop.beyond ? rate <= 0.0 : rate >= 0.0))
      leg.refused = "the guiding centre moves away from its stop at distance " + std::to_string(stop.r) + " (at " +
                    std::to_string(g) + ")";
    else if (k.period(x) * v * kMinTurns > r)
      leg.refused = "the spin turns " + std::to_string(r / (k.period(x) * v)) + " times while the body crosses its " +
                    "distance to the nearest centre (at least " + std::to_string(kMinTurns) + " for one turn a step)";
    if (!leg.refused.empty()) break;
    // A step that would cross the stop lands on it by the guiding centre's rate (its path's curvature and
    // the force bend it by less than a step's change of the rate); one that has crossed it steps back.
    double h = (stop.r - g) / rate;
    if (!passed && h > eta * r / v) {
      h = eta * r / v;
    } else if (++landings > kMaxLandings) {
      leg.refused = "no landing on its stop at distance " + std::to_string(stop.r) + " in " + std::to_string(kMaxLandings) +
                    " steps (at " + std::to_string(g) + ")";
      break;
    }
    h = std::min(h, t_span - leg.t);
    NullObserver none;
    integrate<Seq>(k, x, h, 1, none);  // one step of the table (composition.hpp), a turn for each kick
    leg.t += h;
    ++leg.steps;
  }
  leg.averaged_end = k.to_physical(x);
  corrected(Onto::real);
  return leg;
}

}  // namespace bodypoint::splitting
