// far-ip, the far-field collocation (lib/core/methods/bodypoint/far_field.hpp): its quadrature, free flight, the far
// pass at steps of tens of radians of spin against the long-double reference, and its refusals.
#include "common.hpp"
#include "bodypoint/far_field.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/run.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace bodypoint {
namespace {

// The quadrature integrates a polynomial of its degree exactly: only rounding remains (a sum of n + 1
// terms of size 1, with the inverse of a well-conditioned Chebyshev matrix).
constexpr double kQuadratureRounding = 1e-13;
// Free flight is the exact drift whatever the step: rounding of a few dozen rotations.
constexpr double kFreeFlightRounding = 1e-13;
// The far pass of bench/far_field.py at steps of 20 to 40 rad of spin, against odeint-rkf78 in long
// double at tol 1e-18: the collocation resolves the step (far_field.hpp, points_for), so what is left
// is rounding over a few dozen steps; lp-kl6 at 2.75 rad per step errs 5.1e-11 on the same pass.
constexpr double kFarPassError = 1e-12;

TEST(FarField, ChebyshevQuadratureIsExactForPolynomials) {
  for (int n : {1, 2, 16, 41, 120}) {
    const far_field::Nodes nd = far_field::chebyshev_nodes(n);
    ASSERT_EQ(nd.sigma.size(), n + 1);
    EXPECT_EQ(nd.sigma(0), 0.0);
    EXPECT_EQ(nd.sigma(n), 1.0);
    for (int k : {0, 1, n / 2, n}) {
      const Eigen::VectorXd f = nd.sigma.array().pow(static_cast<double>(k)).matrix();
      const Eigen::VectorXd integral = nd.Q * f;
      for (int i = 0; i <= n; ++i)
        EXPECT_NEAR(integral(i), std::pow(nd.sigma(i), k + 1) / (k + 1), kQuadratureRounding) << "n " << n << " k " << k;
    }
  }
}

TEST(FarField, PointsFollowTheSpinAndTheHelixRadius) {
  using far_field::points_for;
  // No spin to follow: the fewest points, for the force's slow change alone.
  EXPECT_EQ(points_for(0.0, 0.0), far_field::kMinPoints);
  // More radians per step, and a wider helix against the distance (more harmonics), take more points.
  EXPECT_GT(points_for(40.0, 4e-4), points_for(20.0, 4e-4));
  EXPECT_GT(points_for(20.0, 0.02), points_for(20.0, 4e-4));
  // The k-th harmonic is (rho/r)^k of the force: at rho/r = 0.02 the first below kAliasShare is the 8th
  // (0.02^8 = 2.6e-14), plus the pull-back's shift: 9 harmonics, 9/2 points per radian.
  EXPECT_EQ(points_for(20.0, 0.02), static_cast<int>(std::ceil(0.5 * 9 * 20.0)) + far_field::kExtraPoints);
  // A step that would need more than kMaxPoints is refused, not given them.
  EXPECT_EQ(points_for(1e6, 0.5), -1);
}

/// Thesis table 3.1 with the far pass's changes (bench/far_field.py): Kz = 0.1 (helix radius 0.02)
/// and d = 50, so the body stays 50 from the centre.
Scene far_pass(double Kz = 0.1) {
  SceneParams sp;
  sp.start.Kz = Kz;
  sp.start.d = 50.0;
  return thesis_scene(sp);
}
constexpr double kFarPassEnd = 80.0;

/// The spin's rate (B/D)|K1| of the scene's body.
double spin_rate(const Body& b) { return std::abs(b.p.B) / b.p.D() * to_momenta(b.p, b.s0).K1.norm(); }

TEST(FarField, FreeFlightIsTheExactHelixAtAnyStep) {
  Scene s = far_pass(5.0);
  s.centres.front().A = 0.0;
  const Body& b = s.bodies.front();
  const State exact = helix_state(b.p, b.s0, kFarPassEnd);
  for (double radians : {3.0, 30.0, 100.0}) {
    const long steps = std::lround(spin_rate(b) * kFarPassEnd / radians);
    const RunResult r = run(method_or_throw("far-ip"), b, s.centres, FixedSteps{kFarPassEnd / static_cast<double>(steps), steps});
    EXPECT_LT(test::rel_err(r.final.R, exact.R), kFreeFlightRounding) << radians << " rad per step";
    EXPECT_LT(test::rel_err(r.final.v, exact.v), kFreeFlightRounding) << radians << " rad per step";
  }
}

TEST(FarField, FarPassAtTensOfRadiansPerStepMeetsTheReference) {
  const Scene s = far_pass();
  const Body& b = s.bodies.front();
  const State ref = reference_state(b, s.centres, kFarPassEnd, 1e-18L);
  const double turned = spin_rate(b) * kFarPassEnd;
  for (double radians : {20.0, 40.0}) {
    const long steps = std::lround(turned / radians);
    const RunResult r = run(method_or_throw("far-ip"), b, s.centres, FixedSteps{kFarPassEnd / static_cast<double>(steps), steps});
    const double err = std::max(test::rel_err(r.final.R, ref.R), test::rel_err(r.final.v, ref.v));
    std::printf("  far pass, %.0f rad per step: error %.2e, %.2f force evaluations per radian\n", radians, err,
                static_cast<double>(r.force_evals) / turned);
    EXPECT_LT(err, kFarPassError) << radians << " rad per step";
  }
}

TEST(FarField, AStepTooLongForTheEncounterFailsWithItsReason) {
  // Table 3.1 passes 10 from the centre: one step over the whole encounter cannot converge.
  const Scene s = test::table31();
  const Body& b = s.bodies.front();
  try {
    run(method_or_throw("far-ip"), b, s.centres, FixedSteps{25.0, 2});
    FAIL() << "a step of 25 through the encounter was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is too long for the"), std::string::npos) << e.what();
  }
}

TEST(FarField, RefusesAForceLawOtherThanCoulombs) {
  Scene s = test::table31();
  s.centres.front().law = ForceLaw::thesis_code;
  EXPECT_NE(refusal(method_or_throw("far-ip"), s.bodies.front(), s.centres).find("Coulomb"), std::string::npos);
}

TEST(FarField, ABodyAtRestIsAnErrorNotANumber) {
  Scene s = far_pass();
  Body& b = s.bodies.front();
  // K1 = m v + B w = 0: v = -(B/m) w.
  b.s0.v = -(b.p.B / b.p.m) * b.s0.w;
  try {
    run(method_or_throw("far-ip"), b, s.centres, FixedSteps{0.1, 10});
    FAIL() << "a run with K1 = 0 returned";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("|K1| > 0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace bodypoint
