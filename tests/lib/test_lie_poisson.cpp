// Exact Lie-Poisson splitting: exactness on the helix, invariants to round-off, time reversibility,
// bounded energy error without drift, several centres, force-evaluation counts, the round-off floor.
// The Kepler split (kep-*), whose two flows are exact too, shares the helix and invariant tests and is
// exact for a material point.
#include "bodypoint/field.hpp"
#include "bodypoint/detail/monitor.hpp"
#include "bodypoint/kepler.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/scenes.hpp"
#include "bodypoint/splitting/classic.hpp"
#include "bodypoint/splitting/kahan_li.hpp"
#include "bodypoint/splitting/kepler_split.hpp"
#include "bodypoint/splitting/lie_poisson.hpp"
#include "bodypoint/splitting/sofroniou_spaletta.hpp"
#include "bodypoint/splitting/yoshida.hpp"
#include "common.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace bodypoint {
namespace {

namespace sp = splitting;

// One step of up to 35 stages on numbers of size |R| <= ~1e3: a few hundred roundings. The steps go up
// to h = 10 (a rotation of ~70 rad): the phase is known to relative eps, so at h = 50 (~340 rad,
// summed over the stages of lp-y8 ~4000 rad) the phase error alone reaches 2e-13.
constexpr double kHelixTol = 1e-13;
// Issue #3: K2Q and |K2|^2 conserved to 1e-13 relative at every step, for h from 1e-4 to 1. Each
// exact rotation of K2 changes |K2| by rounding only, so the deviation random-walks as ~eps sqrt(n)
// over n rotations (measured 1.3e-13 after 5.4e5 rotations of lp-y8); runs here are capped at 1e4
// steps (<= 3.5e5 rotations).
constexpr double kInvariantTol = 1e-13;
constexpr long kInvariantSteps = 10000;
// Forward then backward over an encounter: round-off of ~1e4 sub-steps, amplified by the
// encounter's sensitivity; issue #3 asks for ~1e-12.
constexpr double kReversibilityTol = 1e-12;
// Energy "drift": the fitted linear trend over the whole run, as a fraction of the maximal error.
constexpr double kMaxDriftFraction = 0.1;
// Lie-Trotter is not symmetric: its round trip misses by the method's error, far above rounding.
constexpr double kNotSymmetricFactor = 1e3;
// Control: RK4's energy error on the bound orbit grows linearly (measured fitted drift 99.6%).
constexpr double kRk4MinDriftFraction = 0.5;
/// The bound orbit's energy (exactly -0.5745) is negative; its radius stays in [0.82, 1.0] in the exact
/// flow, and 1.05 allows for the method's error (lp-y4 at h = 0.01: |dE/E| ~ 1e-8).
constexpr double kBoundEnergyBelow = -0.5;
constexpr double kBoundOrbitMaxR = 1.05;
// Two force sums of two terms each differ by a few roundings of the larger term.
constexpr double kForceSumTol = 4e-15;
// lp-y6 at h = 0.01 on the two-centre scene: measured 1e-13; a broken kick sum would give O(1e-3).
constexpr double kTwoCentreEnergyTol = 1e-11;
// lp-kl8 at h = 0.05 against the analytic hyperbola (t = 50): rounding and the h^8 term only.
constexpr double kRutherfordTolR = 1e-13;
constexpr double kRutherfordTolV = 1e-12;
// The Kepler split of a material point is one exact Kepler flow per stage: only the universal
// variable's solution to 4 eps and the sums' rounding err, over <= 500 steps of t = 50 (measured
// 1e-15..4e-15 in R and v against the long-double Kepler reference).
constexpr double kKeplerSplitExactTol = 1e-13;
// The three-part Kepler split's order is measured between this step and its half on the two-centres
// scene, where every table tested is in its asymptotic range (errors 1e-13..1e-3) and the slope is
// within this much of the order (issue #3's tolerance for measured orders).
constexpr double kThreePartCoarseStep = 0.025;
constexpr double kThreePartSlopeTol = 0.15;

std::vector<const MethodInfo*> lie_methods() {
  std::vector<const MethodInfo*> out;
  for (const MethodInfo& m : methods())
    if (m.family == Family::LiePoisson || m.family == Family::KeplerSplit) out.push_back(&m);
  return out;
}

Scene free_scene(double B) {
  Scene s = test::table31(B);
  s.centres.front().A = 0.0;  // no force: the exact solution is the helix
  return s;
}

// drift_functions against the series summed to convergence in long double (64-bit mantissa): the
// Horner and Estrin sums of <= 9 terms of an alternating series with |x| < 1 round a few times each,
// and the closed form for x >= 1 loses ~x eps in 1 - cos and phi - sin. 8 ulp of double covers both.
constexpr double kDriftFunctionsTol = 8 * 2.220446049250313e-16;

void expect_close_to_series(double x) {
  long double s1 = 0, c1 = 0, s3 = 0, term = 1;  // term = (-x)^k
  long double f1 = 1, f2 = 2, f3 = 6;            // (2k+1)!, (2k+2)!, (2k+3)!
  for (int k = 0; k < 40; ++k) {
    s1 += term / f1;
    c1 += term / f2;
    s3 += term / f3;
    term *= -static_cast<long double>(x);
    f1 *= (2.0L * k + 2) * (2.0L * k + 3);
    f2 *= (2.0L * k + 3) * (2.0L * k + 4);
    f3 *= (2.0L * k + 4) * (2.0L * k + 5);
  }
  const sp::DriftFunctions f = sp::drift_functions(x);
  EXPECT_NEAR(f.S1, static_cast<double>(s1), kDriftFunctionsTol * std::abs(static_cast<double>(s1))) << "x = " << x;
  EXPECT_NEAR(f.C1, static_cast<double>(c1), kDriftFunctionsTol * std::abs(static_cast<double>(c1))) << "x = " << x;
  EXPECT_NEAR(f.S3, static_cast<double>(s3), kDriftFunctionsTol * std::abs(static_cast<double>(s3))) << "x = " << x;
}

// Every branch (4 terms by Horner, 6 and 9 by Estrin, the closed form) and both sides of
// each boundary: the drift's rotation is only as exact as these three functions.
TEST(LiePoisson, DriftFunctionsMatchTheirSeriesInEveryBranch) {
  for (double x : {0.0, 1e-12, 1e-6, 5e-4, 0.000999, 0.001, 0.001001, 0.01, 0.05, 0.0999, 0.1, 0.1001, 0.3, 0.6,
                   0.999, 1.0, 1.001, 2.0, 4.0, 9.0})
    expect_close_to_series(x);
}

TEST(LiePoisson, OneStepOfAnySizeIsTheExactHelixWhenAIsZero) {
  for (double B : {0.0, 0.7}) {
    const Scene s = free_scene(B);
    const Body& b = s.bodies.front();
    for (const MethodInfo* m : lie_methods()) {
      for (double h : {0.1, 1.0, 10.0}) {
        FlatRun spec;
        spec.h = h;
        spec.steps = 1;
        const State got = run(*m, b, s.centres, spec).final;
        const State want = helix_state(b.p, b.s0, h);
        EXPECT_LT(test::rel_err(got.R, want.R), kHelixTol) << m->name << " h=" << h << " B=" << B;
        EXPECT_LT(test::rel_err(got.w, want.w), kHelixTol) << m->name << " h=" << h << " B=" << B;
        EXPECT_LT(test::rel_err(got.v, want.v), kHelixTol) << m->name << " h=" << h << " B=" << B;
      }
    }
  }
}

TEST(LiePoisson, MaterialPointDoesNoSpinWork) {
  // B = 0: the Spin = false kernel never touches K2, so w stays bitwise constant.
  const Scene s = test::table31(0.0);
  Body b = s.bodies.front();
  b.s0.w = Vec3(0.3, -1.7, 2.9);
  FlatRun spec;
  spec.h = 0.01;
  spec.steps = 5000;
  for (const char* name : {"lp-y4", "lp-kl8", "thesis-y6", "kep-kl6"}) {
    const State f = run(method_or_throw(name), b, s.centres, spec).final;
    EXPECT_EQ(f.w, b.s0.w) << name;
  }
}

TEST(LiePoisson, InvariantsConservedToRoundOffAtEveryStep) {
  const Scene s = test::table31(0.7);
  const Body& b = s.bodies.front();
  const double K2Q0 = total_angular_momentum(b.p, b.s0, Vec3::Zero()).norm();
  for (const MethodInfo* m : lie_methods()) {
    for (double h : {1e-4, 1e-3, 1e-2, 1e-1, 1.0}) {
      FlatRun spec;
      spec.h = h;
      spec.steps = std::min(kInvariantSteps, std::lround(100.0 / h));
      spec.track_invariants = true;
      const RunResult r = run(*m, b, s.centres, spec);
      ASSERT_TRUE(r.invariants && r.invariants->has_K2Q);
      EXPECT_LT(r.invariants->max_rel_dK2sq, kInvariantTol) << m->name << " h=" << h;
      EXPECT_LT(r.invariants->max_abs_dK2Q / K2Q0, kInvariantTol) << m->name << " h=" << h;
    }
  }
}

template <const auto& Ops>
double reversibility_error(double h, long n) {
  const Scene s = test::table31(0.7);
  const Body& b = s.bodies.front();
  sp::LiePoissonKernel<OriginCentre, true> k(b.p, OriginCentre{s.centres.front().A});
  sp::LieState x = k.initial_state(b.s0);
  sp::NullObserver none;
  sp::integrate<Ops>(k, x, h, n, none);
  sp::integrate<Ops>(k, x, -h, n, none);
  const Momenta q = sp::from_lie(x), q0 = to_momenta(b.p, b.s0);
  return std::max({test::rel_err(q.R, q0.R), test::rel_err(q.K1, q0.K1), test::rel_err(q.K2, q0.K2)});
}

constexpr auto kVerletOps = sp::flatten(sp::verlet_kdk);
constexpr auto kStrangOps = sp::flatten(sp::strang_dkd_table);
constexpr auto kY4Ops = sp::flatten(sp::yoshida4);
constexpr auto kY6Ops = sp::flatten(sp::yoshida6);
constexpr auto kKl8Ops = sp::flatten(sp::kahan_li8);
constexpr auto kSs10Ops = sp::flatten(sp::sofroniou_spaletta10);
constexpr auto kEulerOps = sp::flatten(sp::euler);

TEST(LiePoisson, SymmetricMethodsAreTimeReversible) {
  // Table 3.1 over the whole encounter (t = 50), forward with h then back with -h.
  EXPECT_LT(reversibility_error<kVerletOps>(0.05, 1000), kReversibilityTol);
  EXPECT_LT(reversibility_error<kStrangOps>(0.05, 1000), kReversibilityTol);
  EXPECT_LT(reversibility_error<kY4Ops>(0.05, 1000), kReversibilityTol);
  EXPECT_LT(reversibility_error<kY6Ops>(0.1, 500), kReversibilityTol);
  EXPECT_LT(reversibility_error<kKl8Ops>(0.1, 500), kReversibilityTol);
  EXPECT_LT(reversibility_error<kSs10Ops>(0.2, 250), kReversibilityTol);
  // Control: Lie-Trotter is not symmetric, and the same check sees it.
  EXPECT_GT(reversibility_error<kEulerOps>(0.05, 1000), kNotSymmetricFactor * kReversibilityTol);
}

/// Least-squares slope of y against x.
double trend(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0, n = static_cast<double>(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

/// Drift of |E - E0|/|E0| over a run: (fitted slope x duration) / max error.
double energy_drift_fraction(const std::string& method, const Body& b, const std::vector<Centre>& cs,
                             double h, long n, double* max_err, double* r_max = nullptr) {
  FlatRun spec;
  spec.h = h;
  spec.steps = n;
  spec.every = n / 1000;
  std::vector<double> t, e;
  double r_far = 0.0;
  SampleSink sink = [&](const Sample& s) {
    t.push_back(s.t);
    e.push_back(s.rel_dE);
    r_far = std::max(r_far, s.s.R.norm());
  };
  const RunResult r = run(method_or_throw(method), b, cs, spec, &sink);
  *max_err = r.invariants->max_rel_dE;
  if (r_max) *r_max = r_far;
  return std::abs(trend(t, e)) * (h * static_cast<double>(n)) / *max_err;
}

TEST(LiePoisson, EnergyErrorBoundedWithoutDriftOverAMillionSteps) {
  // Table 3.1: the whole encounter and 10^6 steps.
  {
    const Scene s = test::table31(0.7);
    double max_err = 0;
    const double drift = energy_drift_fraction("lp-y4", s.bodies.front(), s.centres, 0.05, 1000000, &max_err);
    std::printf("  table 3.1, lp-y4 h=0.05, 1e6 steps: max rel dE %.2e, drift fraction %.3f\n", max_err, drift);
    EXPECT_LT(drift, kMaxDriftFraction);
  }
  // A bound orbit (attracting centre, E0 = -0.5745, r between 0.82 and 1.0, period ~5: 10^4 periods)
  // is the harder case; RK4 is the control that shows the fit detects a drift when there is one.
  Scene s;
  s.centres.push_back({Vec3::Zero(), 1.0});
  const BodyPoint p{1.0, 0.7, 1.0};
  s.bodies.push_back({p, to_state(p, Momenta{Vec3(1, 0, 0), Vec3(0, 0.8, 0), Vec3(0, 0.3, 0.2)}), "orbit"});
  ASSERT_LT(energy(p, OriginCentre{1.0}, s.bodies.front().s0), kBoundEnergyBelow) << "the orbit must be bound";
  double lp_err = 0, rk_err = 0, lp_r = 0, rk_r = 0;
  const double lp_drift = energy_drift_fraction("lp-y4", s.bodies.front(), s.centres, 0.01, 1000000, &lp_err, &lp_r);
  const double rk_drift = energy_drift_fraction("rk4", s.bodies.front(), s.centres, 0.01, 1000000, &rk_err, &rk_r);
  std::printf("  bound orbit, h=0.01, 1e6 steps: lp-y4 max rel dE %.2e drift fraction %.3f r_max %.3f; "
              "rk4 max rel dE %.2e drift fraction %.3f\n", lp_err, lp_drift, lp_r, rk_err, rk_drift);
  EXPECT_LT(lp_r, kBoundOrbitMaxR) << "lp-y4 left the bound orbit";
  EXPECT_LT(rk_r, kBoundOrbitMaxR) << "rk4 left the bound orbit";
  EXPECT_LT(lp_drift, kMaxDriftFraction);
  EXPECT_GT(rk_drift, kRk4MinDriftFraction) << "control: RK4's energy error grows linearly";
}

TEST(LiePoisson, SeveralCentresSumForcesAndKeepEnergyBounded) {
  CentreList two{{{Vec3(0, 0, 0), -2.0}, {Vec3(30, 5, 0), 1.5}}};
  const Vec3 R(3, -4, 1);
  const Vec3 want = OriginCentre{-2.0}.force(R) + OriginCentre{1.5}.force(R - Vec3(30, 5, 0));
  EXPECT_LT((two.force(R) - want).norm(), kForceSumTol * want.norm());

  Scene s = test::table31(0.7);
  s.centres.push_back({Vec3(40, 6, 0), -1.0});
  FlatRun spec;
  spec.h = 0.01;
  spec.steps = 8000;
  spec.track_invariants = true;
  const RunResult r = run(method_or_throw("lp-y6"), s.bodies.front(), s.centres, spec);
  EXPECT_FALSE(r.invariants->has_K2Q) << "K2Q is not an integral with two centres";
  EXPECT_LT(r.invariants->max_rel_dK2sq, kInvariantTol);
  EXPECT_LT(r.invariants->max_rel_dE, kTwoCentreEnergyTol);
}

TEST(LiePoisson, ForceEvaluationsPerStepAsAdvertised) {
  const Scene s = test::table31(0.7);
  FlatRun spec;
  spec.h = 0.1;
  spec.steps = 100;
  for (const MethodInfo& m : methods()) {
    if (m.family != Family::LiePoisson && m.family != Family::Thesis) continue;
    const RunResult r = run(m, s.bodies.front(), s.centres, spec);
    long expected = m.evals_per_step * spec.steps;
    // Tables that start and end with a kick share the force at each step boundary; the very first
    // kick needs one evaluation of its own.
    if (m.family == Family::LiePoisson && m.stages > m.evals_per_step) expected += 1;
    EXPECT_EQ(r.force_evals, expected) << m.name;
  }
}

// Issue #3: the floor of the high-order methods near 1e-14 relative, not 1e-12. Measured over the
// steps below: 0.3e-14 to 1.7e-14 (the scatter is the rounding of ~1e5 sub-steps).
constexpr double kFloorTol = 5e-14;

TEST(LiePoisson, RoundOffFloorNearOneEMinusFourteen) {
  // Compensated summation of R and K1 keeps the floor of lp-kl8 on table 3.1 (up to 1.7e5 sub-steps,
  // |R| up to 200) near 1e-14 relative.
  const Scene s = test::table31(0.7);
  // Reference at tolerance 1e-18 in long double: at 1e-16 its own error is ~7e-15 relative.
  const State ref = reference_state(s.bodies.front(), s.centres, 50.0, 1e-18L);
  double worst = 0;
  for (double h : {0.005, 0.01, 0.02}) {
    FlatRun spec;
    spec.steps = std::lround(50.0 / h);
    spec.h = 50.0 / static_cast<double>(spec.steps);
    const State got = run(method_or_throw("lp-kl8"), s.bodies.front(), s.centres, spec).final;
    const double e = test::rel_err(got.R, ref.R);
    std::printf("  lp-kl8 h=%g table 3.1: final relative position error %.2e\n", h, e);
    worst = std::max(worst, e);
  }
  EXPECT_LT(worst, kFloorTol);
}

TEST(LiePoisson, MaterialPointFollowsTheRutherfordHyperbola) {
  const Scene s = test::table31(0.0);
  const State exact = kepler_body_state(s.bodies.front(), s.centres.front(), 50.0);
  FlatRun spec;
  spec.h = 0.05;
  spec.steps = 1000;
  const State got = run(method_or_throw("lp-kl8"), s.bodies.front(), s.centres, spec).final;
  EXPECT_LT(test::rel_err(got.R, exact.R), kRutherfordTolR);
  EXPECT_LT(test::rel_err(got.v, exact.v), kRutherfordTolV);
}

TEST(LiePoisson, KeplerSplitIsExactForAMaterialPoint) {
  // B = 0: H_S = 0 and every stage is an exact Kepler flow, whatever the step (the Lie-Poisson
  // split at h = 1 misses by ~1e-3 here).
  const Scene s = test::table31(0.0);
  const Body& b = s.bodies.front();
  const State exact = kepler_body_state(b, s.centres.front(), 50.0);
  int checked = 0;
  for (const MethodInfo& m : methods()) {
    if (m.family != Family::KeplerSplit) continue;
    for (double h : {0.1, 1.0, 5.0}) {
      FlatRun spec;
      spec.h = h;
      spec.steps = std::lround(50.0 / h);
      const State got = run(m, b, s.centres, spec).final;
      EXPECT_LT(test::rel_err(got.R, exact.R), kKeplerSplitExactTol) << m.name << " h=" << h;
      EXPECT_LT(test::rel_err(got.v, exact.v), kKeplerSplitExactTol) << m.name << " h=" << h;
    }
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

// The Kepler flow's rounding falls either way: 3,000 flows of t = 1 on a bound orbit (e = 0.44, 200
// revolutions) from 8 starts a unit in the last place apart. Each start's energy moves by a random walk
// of roundings (measured -5e-15..+7e-15); their mean is ~4e-15 at most. With g = t - mu G3 and the
// closed-form Stumpff functions every flow lost a rounding one way: the mean was -9.1e-14 (8 of 8 below
// -8e-14), which over 20 revolutions put kep-y4 at h = 1 2e-11 off the Kepler orbit.
constexpr double kKeplerFlowMeanDrift = 2e-14;
constexpr int kKeplerFlowStarts = 8;
constexpr int kKeplerFlowSteps = 3000;

TEST(LiePoisson, KeplerFlowRoundsEitherWay) {
  double mean = 0.0;
  for (int k = 0; k < kKeplerFlowStarts; ++k) {
    Vec3 X(1.0, 0.0, 0.0), V(0.0, 1.2, 0.0);
    for (int j = 0; j <= k; ++j) V.y() = std::nextafter(V.y(), 2.0);
    const double E0 = 0.5 * V.squaredNorm() - 1.0 / X.norm();
    for (int i = 0; i < kKeplerFlowSteps; ++i) {
      const KeplerCoefficients<double> c = kepler_flow(1.0, X.norm(), X.dot(V), V.squaredNorm(), 1.0);
      const Vec3 dX = c.f_minus_1 * X + c.g * V, dV = c.fd * X + c.gd_minus_1 * V;
      X += dX;
      V += dV;
    }
    mean += (0.5 * V.squaredNorm() - 1.0 / X.norm() - E0) / kKeplerFlowStarts;
  }
  EXPECT_LT(std::abs(mean), kKeplerFlowMeanDrift);
}

// kep-y4's Kepler stages on a bound orbit walk, not drift (Brouwer's law): the Yoshida substeps w1 h, w0 h
// (< 0: the forward flow of the reversed velocity), w1 h at h = P/100 on an e = 0.5 ellipse by the Kepler
// split's own flow of its compensated pairs, 4 x 10^5 steps (4,000 periods) from 16 starting phases. The
// starts' mean relative energy error is the drift, their rms the walk's size. With the coefficients in double:
// rms 4.1e-13 (8 starts, 2 x 10^5 steps); in long double from the pairs rounded to double: mean
// -2.9e-14, rms 4.6e-14 (a bias of 6.5e-4 unit roundoffs a step); from the pairs themselves: mean -9.5e-16,
// rms 1.7e-14. A mean within 2.4 standard errors of the walk's (rms/4), 2.9x below the rounded pairs' drift.
constexpr double kKeplerWalkMean = 1e-14;
constexpr double kKeplerWalkRms = 3e-14;  // 1.8x the walk, 1.5x below the rounded pairs'
constexpr int kKeplerWalkStarts = 16;
constexpr long kKeplerWalkSteps = 400000;

double kepler_stage_energy_error(double phase) {
  constexpr double e = 0.5, mu = 1.0, h = 2.0 * std::numbers::pi / 100.0;
  const double rp = 1.0 - e, vp = std::sqrt(mu * (1.0 + e) / rp);
  Vec3 X(rp * std::cos(phase), rp * std::sin(phase), 0.0), V(-vp * std::sin(phase), vp * std::cos(phase), 0.0);
  Vec3 X_err = Vec3::Zero(), V_err = Vec3::Zero();
  const auto energy = [&] {
    const Vec3 Xs = X - X_err, Vs = V - V_err;
    return 0.5L * static_cast<long double>(Vs.squaredNorm()) - mu / std::sqrt(static_cast<long double>(Xs.squaredNorm()));
  };
  const long double E0 = energy();
  const double w1 = 1.0 / (2.0 - std::cbrt(2.0)), w0 = 1.0 - 2.0 * w1;
  for (long n = 0; n < kKeplerWalkSteps; ++n) {
    for (const double w : {w1, w0, w1}) sp::kepler_flow_compensated(mu, 1.0, Vec3::Zero(), X, X_err, V, V_err, w * h);
  }
  return static_cast<double>((energy() - E0) / std::abs(E0));
}

TEST(LiePoisson, KeplerStagesOfABoundOrbitWalkAsBrouwersLaw) {
  double sum = 0.0, sum_sq = 0.0;
  for (int k = 0; k < kKeplerWalkStarts; ++k) {
    const double dE = kepler_stage_energy_error(0.37 * (k + 1) + 0.1);
    sum += dE;
    sum_sq += dE * dE;
  }
  EXPECT_LT(std::abs(sum / kKeplerWalkStarts), kKeplerWalkMean);
  EXPECT_LT(std::sqrt(sum_sq / kKeplerWalkStarts), kKeplerWalkRms);
}

// Stumpff functions against long double over |z| <= 400 (both branches, the quartered range between):
// measured 9 roundings at most for c3 relative to its value; the closed forms alone left 36 at z = 0.11.
constexpr double kStumpffC3Tol = 16 * 2.220446049250313e-16;

TEST(LiePoisson, StumpffFunctionsAreAccurateInEveryBranch) {
  for (double z = -400.0; z <= 400.0; z += 0.0137) {
    double c[4];
    long double C[4];
    stumpff(z, c);
    stumpff(static_cast<long double>(z), C);
    EXPECT_NEAR(c[3], static_cast<double>(C[3]), kStumpffC3Tol * std::abs(static_cast<double>(C[3]))) << "z = " << z;
  }
}

TEST(LiePoisson, KeplerSplitOfSeveralCentresKeepsItsOrder) {
  // Two centres: the first is the Kepler centre, the second a third part (kicks flanking each Kepler
  // flow, composition.hpp flatten_three). The composition keeps the table's order: slopes between
  // h = 0.025 and 0.0125 on the two-centres scene (measured 2.00, 4.00, 6.04), |K2|^2 to round-off.
  const NamedScene ns = named_scene("two-centres");
  const Body& b = ns.scene.bodies.front();
  const State ref = reference_state(b, ns.scene.centres, ns.t_end, 1e-18L);
  for (const char* name : {"kep-verlet", "kep-y4", "kep-kl6"}) {
    const MethodInfo& m = method_or_throw(name);
    EXPECT_EQ(refusal(m, b, ns.scene.centres), "") << name;
    double err[2] = {0.0, 0.0};
    for (int k = 0; k < 2; ++k) {
      FlatRun spec;
      spec.h = kThreePartCoarseStep / (1 << k);
      spec.steps = std::lround(ns.t_end / spec.h);
      spec.track_invariants = true;
      const RunResult r = run(m, b, ns.scene.centres, spec);
      err[k] = std::max(test::rel_err(r.final.R, ref.R), test::rel_err(r.final.v, ref.v));
      EXPECT_LT(r.invariants->max_rel_dK2sq, kInvariantTol) << name;
    }
    EXPECT_NEAR(std::log2(err[0] / err[1]), m.order, kThreePartSlopeTol) << name << " " << err[0] << " " << err[1];
  }
  // The thesis code's force law is not Coulomb's: no Kepler flow for it.
  Scene code = test::table31(0.7);
  code.centres.front().law = ForceLaw::thesis_code;
  EXPECT_NE(refusal(method_or_throw("kep-kl8"), code.bodies.front(), code.centres).find("Coulomb"), std::string::npos);
}

}  // namespace
}  // namespace bodypoint
