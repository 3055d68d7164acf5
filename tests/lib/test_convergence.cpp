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
#include <optional>
#include <string>
#include <vector>

namespace bodypoint {
namespace {

// Slope within 0.15 of the order: the tolerance issue #3 asks for; the ladders below are
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
// kep-kl8 (the Kepler split, B = 0.7) approaches order 8 from above: its h^8 term is small against the
// h^10 term over the whole window above round-off (slopes of successive pairs on the orbit 10.4, 9.8,
// 8.5, 8.2, 8.1 as h falls from 0.18 to 0.044), so the fitted slope is 8.3. The order is asserted
// from below as for every method; above, this much is allowed.
constexpr double kKeplerSplit8Excess = 0.5;

struct Case {
  std::string method;
  double expected_order;
  double h0;              // largest step of the ladder
  bool on_orbit = false;  // measure on orbit() instead of encounter()
  double above = kSlopeTol;  // allowed excess over the order
  double below = kSlopeTol;  // allowed shortfall
};

/// The ladder of a method of this order: the largest step above the asymptotic range's upper end,
/// and the bound orbit for order 8 (the encounter's error reaches round-off before the slope settles).
Case default_case(const MethodInfo& m) {
  const double order = m.order;
  if (m.order >= 10) return {m.name, order, 1.5, true, 3.0, order - kSs10Lowest};
  if (m.order >= 8) return {m.name, order, 1.0, true};
  if (m.order >= 6) return {m.name, order, 0.5};
  if (m.order >= 3) return {m.name, order, 0.2};
  return {m.name, order, m.order == 1 ? 0.01 : 0.1};
}

/// Where a method's window differs from its order's: six-stage fourth-order tables are accurate
/// enough to start at h = 0.5; lp-rkn6 (and lp-kl6 at B = 0) reach round-off on the encounter before
/// their slope settles; on the encounter at B = 0.7 Ruth 3's error is hidden by conjugacy (the orbit
/// shows it), while lp-y8's settles there; kep-kl8 (kKeplerSplit8Excess).
struct Override {
  const char* method;
  std::optional<double> B;  // only at this B (both when empty)
  double h0;
  bool on_orbit;
  double above = kSlopeTol;
};
const Override kOverrides[] = {
    {"lp-bm4", {}, 0.5, false},   {"lp-rkn4", {}, 0.5, false}, {"lp-rkn6", {}, 0.5, true},
    {"lp-ruth3", 0.7, 0.2, true}, {"lp-y8", 0.7, 1.0, false},  {"lp-kl6", 0.0, 0.5, true},
    {"kep-kl8", 0.7, 1.0, true, kKeplerSplit8Excess},
};

/// Whether this file measures the order of a family's methods at this B, by family: a family added to
/// the catalogue must be placed here (no default: the compiler's -Wswitch names it), so none is left
/// unmeasured without a reason.
bool measured_here(Family f, double B) {
  switch (f) {
    case Family::Odeint:
    case Family::LiePoisson: return true;
    // At B = 0 exact whatever its step (test_lie_poisson.cpp, KeplerSplitIsExactForAMaterialPoint).
    case Family::KeplerSplit: return B != 0.0;
    // At B != 0 first order whatever its table: ThesisFamilyIsFirstOrderForBodyPoint.
    case Family::Thesis: return B == 0.0;
    // Fictitious steps: tests/adaptive/test_adaptive.cpp (ConvergenceOrderInTheFictitiousStep...); ks is
    // exact in its fictitious time (test_adaptive.cpp, against the analytic hyperbola).
    case Family::TimeTransformed:
    case Family::Regularised: return false;
    // Peers with their own step control: their order is theirs, not a claim of this project.
    case Family::OdeintAdaptive:
    case Family::Gsl:
    case Family::Sundials:
    case Family::Extrapolated: return false;
    // Spectral in its step (its error is its points' resolution, not C h^p): tests/lib/test_far_field.cpp.
    case Family::FarField: return false;
  }
  return false;
}

/// The cases at this B, generated from the registry by family (so a table added to the catalogue is
/// measured too).
std::vector<Case> cases_at(double B) {
  std::vector<Case> cases;
  for (const MethodInfo& m : methods()) {
    const bool wanted = measured_here(m.family, B);
    if (!wanted) continue;
    Case c = default_case(m);
    for (const Override& o : kOverrides)
      if (m.name == o.method && (!o.B || *o.B == B)) {
        c.h0 = o.h0;
        c.on_orbit = o.on_orbit;
        c.above = o.above;
      }
    cases.push_back(c);
  }
  return cases;
}

TEST(Convergence, EveryOverrideNamesAMethod) {
  for (const Override& o : kOverrides) EXPECT_NE(find_method(o.method), nullptr) << o.method;
}

double measured_slope(const Case& c, double B) {
  const Scene s = c.on_orbit ? orbit(B) : encounter(B);
  const double kTEnd = c.on_orbit ? kOrbitTEnd : test_t_end;
  const Body& body = s.bodies.front();
  const State ref = B == 0.0 ? kepler_body_state(body, s.centres.front(), kTEnd)
                             : reference_state(body, s.centres, kTEnd);
  const std::string label = c.method + (c.on_orbit ? " orbit" : " encounter") + (B == 0.0 ? " B=0" : " B=0.7");
  return test::ladder_slope(label, [&](int k) {
    FlatRun spec;
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

TEST(Convergence, NominalOrderForBodyPoint) {
  for (const Case& c : cases_at(0.7)) {
    const double slope = measured_slope(c, 0.7);
    EXPECT_LE(slope, c.expected_order + c.above) << c.method;
    EXPECT_GE(slope, c.expected_order - c.below) << c.method;
  }
}

// With B = 0 the gyroscopic term vanishes and the thesis's schemes are the classical splittings.
TEST(Convergence, NominalOrderForMaterialPoint) {
  for (const Case& c : cases_at(0.0)) {
    const double slope = measured_slope(c, 0.0);
    EXPECT_LE(slope, c.expected_order + c.above) << c.method;
    EXPECT_GE(slope, c.expected_order - c.below) << c.method;
  }
}

TEST(Convergence, ThesisFamilyIsFirstOrderForBodyPoint) {
  // The gyroscopic term w x v is frozen at the start of each step (thesis eq. 2.12): an explicit
  // Euler step of the spin-orbit rotation, so every scheme of the family is first order for B != 0
  // whatever its table (docs/physics.md). Measured, not assumed: the slope is asserted to be 1.
  for (const MethodInfo& m : methods()) {
    if (m.family != Family::Thesis) continue;
    EXPECT_NEAR(measured_slope({m.name, 1, 0.01}, 0.7), 1.0, kSlopeTol) << m.name;
  }
}

}  // namespace
}  // namespace bodypoint
