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

/// What a leg did: its time, steps and why it ended.
struct FarLeg {
  double t = 0.0;
  long steps = 0;
  bool reached_radius = false;  ///< ended at r <= r_stop, before t_span
};

/// The far leg: the table's steps h = eta r/|v| (r: the nearest centre) with E for its kicks, from a
/// real state for the time t_span or until a step ends within r_stop of a centre, the state real again
/// at its end. Error where a turn is too long for the slow scale (kMinTurns).
template <const auto& Seq, class Field>
FarLeg far_leg(FarTurnKernel<Field>& k, LieState& x, double t_span, double eta, double r_stop) {
  using Onto = typename FarTurnKernel<Field>::Onto;
  FarLeg leg;
  k.quiver(x, Onto::averaged);
  while (leg.t < t_span) {
    const double r = nearest_centre(k.lp.field, x.R - x.R_err);
    if (r <= r_stop) {
      leg.reached_radius = true;
      break;
    }
    const double v = k.to_physical(x).v.norm();
    if (k.period(x) * v * kMinTurns > r)
      throw Error("far leg: the spin turns " + std::to_string(r / (k.period(x) * v)) + " times while the body crosses " +
                  "its distance to the nearest centre (at least " + std::to_string(kMinTurns) + " for one turn a step)");
    const double h = std::min(eta * r / v, t_span - leg.t);
    for (std::size_t j = 0; j < Seq.size; ++j) {
      if (Seq.ops[j].part == Part::kick) k.kick(x, Seq.ops[j].c * h);
      else k.drift(x, Seq.ops[j].c * h);
    }
    leg.t += h;
    ++leg.steps;
  }
  k.quiver(x, Onto::real);
  return leg;
}

}  // namespace bodypoint::splitting
