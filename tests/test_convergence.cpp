// Measured convergence orders of every fixed-step method (log-log slope of the final-position error
// against h), for a body-point (B = 0.7) and a material point (B = 0), against independent references:
// Boost.Odeint rkf78 in long double for B != 0, the analytic Rutherford hyperbola for B = 0.
#include "bodypoint/methods.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/scenes.hpp"
#include "common.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace bodypoint {
namespace {

// Slope within 0.15 of the order: the tolerance STYLE.md and issue #3 ask for; the ladders below are
// chosen in the asymptotic range, above the round-off plateau.
constexpr double kSlopeTol = 0.15;
// The two independent references (odeint rkf78 in long double, Kepler's equation) agree this well.
constexpr double kReferenceAgreement = 1e-13;

// The scenes (bodypoint/scenes.hpp): the encounter stopped at its closest approach and two periods of
// a bound orbit.
Scene encounter(double B) { return convergence_encounter(B).scene; }
Scene orbit(double B) { return convergence_orbit(B).scene; }
const double test_t_end = convergence_encounter(0.0).t_end;
const double kOrbitTEnd = convergence_orbit(0.0).t_end;

// For lp-ss10 the order-10 regime lies below the round-off plateau of double precision: in the window
// above it the h^12 term still dominates (measured slopes 11.2 at B = 0 and 12.1 at B = 0.7 on the
// orbit). Only "clearly above order 8" is asserted, which any wrong weight breaks.
constexpr double kSs10Lowest = 9.0;

struct Case {
  std::string method;
  double expected_order;
  double h0;              // largest step of the ladder
  bool on_orbit = false;  // measure on orbit() instead of encounter()
  double above = kSlopeTol;  // allowed excess over the order
  double below = kSlopeTol;  // allowed shortfall
};

double measured_slope(const Case& c, double B) {
  const Scene s = c.on_orbit ? orbit(B) : encounter(B);
  const double kTEnd = c.on_orbit ? kOrbitTEnd : test_t_end;
  const Body& body = s.bodies.front();
  const State ref = B == 0.0 ? kepler_body_state(body, s.centres.front(), kTEnd)
                             : reference_state(body, s.centres, kTEnd);
  const std::string label = c.method + (c.on_orbit ? " orbit" : " encounter") + (B == 0.0 ? " B=0" : " B=0.7");
  return test::ladder_slope(label, [&](int k) {
    RunSpec spec;
    spec.steps = std::lround(kTEnd / c.h0 * std::pow(std::sqrt(2.0), k));
    spec.h = kTEnd / static_cast<double>(spec.steps);
    const RunResult r = run(method_or_throw(c.method), body, s.centres, spec);
    return std::pair{spec.h, test::rel_err(r.final.R, ref.R)};
  });
}

TEST(Convergence, ReferencesAgree) {
  const Scene s = encounter(0.0);
  const State a = kepler_body_state(s.bodies.front(), s.centres.front(), test_t_end);
  const State b = reference_state(s.bodies.front(), s.centres, test_t_end);
  EXPECT_LT(test::rel_err(b.R, a.R), kReferenceAgreement);
}

// Each method is measured where its asymptotic regime is reachable in double precision: the
// close encounter for most, the bound orbit where the encounter's error is too small (high orders
// at B = 0) or where conjugacy hides the order on the encounter (Ruth 3 at B = 0.7).
const Case kSs10{"lp-ss10", 10, 1.5, true, 3.0, 10.0 - kSs10Lowest};

TEST(Convergence, NominalOrderForBodyPoint) {
  const std::vector<Case> cases = {
      {"rk4", 4, 0.2},          {"ab4", 4, 0.1},         {"lp-euler", 1, 0.01},
      {"lp-verlet", 2, 0.1},    {"lp-verlet-dkd", 2, 0.1}, {"lp-ruth3", 3, 0.2, true},
      {"lp-y4", 4, 0.2},        {"lp-bm4", 4, 0.5},      {"lp-y6", 6, 0.5},
      {"lp-rkn4", 4, 0.5},      {"lp-rkn6", 6, 0.5, true},
      {"lp-kl6", 6, 0.5},       {"lp-y8", 8, 1.0},       {"lp-y8d", 8, 1.0, true},
      {"lp-mcl8", 8, 1.0, true}, {"lp-kl8", 8, 1.0, true},
      kSs10};
  for (const Case& c : cases) {
    const double slope = measured_slope(c, 0.7);
    EXPECT_LE(slope, c.expected_order + c.above) << c.method;
    EXPECT_GE(slope, c.expected_order - c.below) << c.method;
  }
}

TEST(Convergence, NominalOrderForMaterialPoint) {
  const std::vector<Case> cases = {
      {"rk4", 4, 0.2},          {"ab4", 4, 0.1},           {"lp-euler", 1, 0.01},
      {"lp-verlet", 2, 0.1},    {"lp-verlet-dkd", 2, 0.1}, {"lp-ruth3", 3, 0.2},
      {"lp-y4", 4, 0.2},        {"lp-bm4", 4, 0.5},        {"lp-y6", 6, 0.5},
      {"lp-rkn4", 4, 0.5},      {"lp-rkn6", 6, 0.5, true},
      {"lp-kl6", 6, 0.5, true}, {"lp-y8", 8, 1.0, true},   {"lp-y8d", 8, 1.0, true},
      {"lp-mcl8", 8, 1.0, true}, {"lp-kl8", 8, 1.0, true}, kSs10,
      // With B = 0 the gyroscopic term vanishes and the thesis's schemes are the classical splittings.
      {"thesis-euler", 1, 0.01}, {"thesis-verlet", 2, 0.1}, {"thesis-ruth3", 3, 0.2},
      {"thesis-fr4", 4, 0.2},   {"thesis-y6", 6, 0.5}};
  for (const Case& c : cases) {
    const double slope = measured_slope(c, 0.0);
    EXPECT_LE(slope, c.expected_order + c.above) << c.method;
    EXPECT_GE(slope, c.expected_order - c.below) << c.method;
  }
}

TEST(Convergence, ThesisFamilyIsFirstOrderForBodyPoint) {
  // The gyroscopic term w x v is frozen at the start of each step (thesis eq. 2.12): an explicit
  // Euler step of the spin-orbit rotation, so every scheme of the family is first order for B != 0
  // whatever its table (shared/PHYSICS.md). Measured, not assumed: the slope is asserted to be 1.
  for (const char* m : {"thesis-euler", "thesis-verlet", "thesis-ruth3", "thesis-fr4", "thesis-y6"})
    EXPECT_NEAR(measured_slope({m, 1, 0.01}, 0.7), 1.0, kSlopeTol) << m;
}

}  // namespace
}  // namespace bodypoint
