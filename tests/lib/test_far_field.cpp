// far-ip, the far-field collocation (lib/core/methods/bodypoint/far_field.hpp): its quadrature, free flight, the far
// pass at steps of tens of radians of spin against the long-double reference, and its refusals. The far leg by
// one turn a step (splitting/far_turn.hpp) against the exact splitting at a fraction of a radian a step.
#include "common.hpp"
#include "bodypoint/bodypoint.hpp"
#include "bodypoint/far_field.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/scattering.hpp"
#include "bodypoint/splitting/catalogue.hpp"
#include "bodypoint/splitting/far_turn.hpp"

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


namespace far_turn {

namespace sp = splitting;

// The far leg's error at r >= 400 on bench/far_turn.cpp's scenes: 1.5e-10 .. 4.6e-9 (the quiver's share the
// leg does not model; at r = 778, 3.0e-10). A bound 2x above the largest.
constexpr double kLegError = 1e-8;
// Without the quiver correction the same leg errs 1.0e-7 at r = 778 (330x): the correction must account for
// at least this factor, or it is not what removes the error.
constexpr double kCorrectionGain = 30.0;
// The exact splitting's reference at 0.03 rad a step (lp-kl8, h = 0.004) errs below 1e-12 on this leg.
constexpr double kReferenceStep = 0.004;

Body arriving(double L, double B = 0.7) {
  SceneParams s;
  s.B = B;
  s.start.L = L;
  return thesis_scene(with_asymptotic_data(s, 3.0, std::numeric_limits<double>::quiet_NaN(), 1.0)).bodies[0];
}

struct LegRun {
  State end;
  sp::FarLeg leg;
  long evals;
};
LegRun leg(const Body& b, double r_stop, double share = sp::kQuiverShare) {
  sp::FarTurnKernel<OriginCentre> k(b.p, OriginCentre{-2.0});
  k.quiver_share = share;
  sp::LieState x = k.initial_state(b.s0);
  const sp::FarLeg l = sp::far_leg<sp::ops_of<sp::KahanLi6>>(k, x, std::numeric_limits<double>::infinity(), 0.1,
                                                             sp::LegStop{Vec3::Zero(), r_stop, false});
  return {k.to_physical(x), l, k.evals()};
}

/// lp-kl8 at about kReferenceStep over time t, by the public API; its evaluations in *evals.
State exact(const Body& b, double t, long* evals) {
  const long n = std::lround(std::ceil(t / kReferenceStep));
  Options o;
  o.track_invariants = false;
  const BodyResult r = integrate_body(b, {Centre{Vec3::Zero(), -2.0}}, find_method("lp-kl8"),
                                      FixedSteps{t / static_cast<double>(n), n}, o);
  *evals = r.run.force_evals;
  return r.run.final;
}

}  // namespace far_turn

TEST(FarTurn, ALegOfOneTurnAStepMeetsTheExactSplittingAtAThousandthOfItsCost) {
  const Body b = far_turn::arriving(3200.0);
  const far_turn::LegRun run = far_turn::leg(b, 800.0);
  ASSERT_TRUE(run.leg.reached);
  long exact_evals = 0;
  const State ref = far_turn::exact(b, run.leg.t, &exact_evals);
  const double error = state_distance(run.end, ref);
  EXPECT_LT(error, far_turn::kLegError);
  EXPECT_LT(run.evals * 1000, exact_evals) << run.evals << " evaluations against " << exact_evals;
  // The quiver correction is what brings the leg there.
  const double uncorrected = state_distance(far_turn::leg(b, 800.0, 0.0).end, ref);
  EXPECT_GT(uncorrected, far_turn::kCorrectionGain * error) << uncorrected << " against " << error;
}

TEST(FarTurn, ItsCostGrowsLikeTheLogarithmOfTheDistance) {
  // Four times the start distance: a leg of steps eta r/|v| takes ln(L/r_stop)/eta steps (2.0x here), where a
  // step capped by the spin takes (L - r_stop)/(|v| h) (4.9x).
  const long near = far_turn::leg(far_turn::arriving(3200.0), 800.0).evals;
  const long far = far_turn::leg(far_turn::arriving(12800.0), 800.0).evals;
  const double log_ratio = std::log(12800.0 / 800.0) / std::log(3200.0 / 800.0);
  EXPECT_LT(static_cast<double>(far), 1.2 * log_ratio * static_cast<double>(near)) << near << " -> " << far;
}

TEST(FarTurn, StopsShortWithItsReasonWhereTheSpinIsTooSlowForATurnAStep) {
  // B = 0.01: the spin turns 0.6 times while the body crosses its distance at r = 400 (3 at the start).
  const far_turn::LegRun run = far_turn::leg(far_turn::arriving(3200.0, 0.01), 400.0);
  EXPECT_FALSE(run.leg.reached);
  EXPECT_NE(run.leg.refused.find("the spin turns"), std::string::npos) << run.leg.refused;
}

}  // namespace
}  // namespace bodypoint
