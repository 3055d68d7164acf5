// The public API (bodypoint.hpp) through the library: integrate() is run() for every way of advancing
// time, outcomes are typed, check_takes() is where an Advance meets a method, and a Stepper continues a
// run as one run of the same steps would.
#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/bodypoint.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/sweep.hpp"
#include "sweep_tasks.hpp"
#include "bodypoint/detail/run_parts.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <tuple>
#include <vector>

namespace bodypoint {
namespace {

/// Continuing a one-step method in segments repeats the same steps from the same states; the state
/// crosses each segment boundary through (R, v, w) and back to the method's variables (R, K1, K2),
/// which rounds it once more: a few ulp per boundary, over 10 boundaries.
constexpr double kSegmentRoundOff = 1e-12;
/// Sample times are t0 + i h with h = 0.01: a few ulp of times of order 1.
constexpr double kTimeRoundOff = 1e-12;

/// Output times inside a step are reached by a shorter step of the same method from the step's start:
/// the sample differs from the exact state by the method's own error at these steps (lp-kl8 and logh-kl8
/// at 0.01, rk4 at h = 1e-3, rk8pd and rkf78 at tol 1e-12, over t = 2 on table 3.1).
constexpr double kOutputTimeError = 1e-10;

Scene thesis() { return thesis_scene(SceneParams{}); }

double rel(const Vec3& a, const Vec3& b) { return (a - b).norm() / b.norm(); }

TEST(Api, IntegrateIsRunForEveryWayOfAdvancingTime) {
  const Scene s = thesis();
  const Body& b = s.bodies.front();
  struct Case {
    const char* method;
    Advance how;
  };
  const std::vector<Case> cases = {
      {"lp-y4", FixedSteps{1e-2, 500}},
      {"rk4", FixedSteps{1e-2, 500}},
      {"logh-kl6", FictitiousSteps{0.05, EndTime{5.0}}},
      {"odeint-dopri5", ControlledSteps{1e-3, 5.0, 1e-9}},
  };
  for (const Case& c : cases) {
    const MethodInfo& m = method_or_throw(c.method);
    const Result r = integrate(s, c.method, c.how);
    ASSERT_EQ(r.outcome, Outcome::ok) << c.method << ": " << r.reason;
    const RunResult direct = run(m, b, s.centres, c.how);
    EXPECT_EQ(r.bodies.front().run.final.R, direct.final.R) << c.method;
    EXPECT_EQ(r.bodies.front().run.final.v, direct.final.v) << c.method;
    EXPECT_EQ(r.bodies.front().run.force_evals, direct.force_evals) << c.method;
    ASSERT_TRUE(r.bodies.front().run.invariants.has_value()) << c.method;
    // Every way of advancing time by step has a companion run for its error estimate, counted in the total.
    const ErrorEstimate& e = r.bodies.front().error;
    EXPECT_TRUE(e.known()) << c.method << ": " << e.basis;
    EXPECT_GT(e.force_evals, 0) << c.method;
    EXPECT_EQ(r.force_evals, direct.force_evals + e.force_evals) << c.method;
  }
}

TEST(Api, AccuracyModeDeliversTheSearchedRunWithItsReport) {
  SceneParams p;
  p.start.Kz = 0.1;
  p.start.d = 0.05;
  const Scene s = thesis_scene(p);
  const Body& b = s.bodies.front();
  const double tol = 1e-8, t_end = 80.0;
  Options quiet;
  quiet.track_invariants = false;
  const Result r = integrate(s, "auto", Accuracy{tol, t_end}, quiet);
  ASSERT_EQ(r.outcome, Outcome::ok) << r.reason;
  const BodyResult& br = r.bodies.front();
  ASSERT_TRUE(br.accuracy.has_value());
  EXPECT_FALSE(br.chosen.empty());
  // auto's method searched as auto searches it (no verification of the delivered run).
  const adaptive::ToleranceResult t = adaptive::run_to_tolerance(*br.method, b, s.centres, Accuracy{tol, t_end}, quiet, false);
  EXPECT_EQ(br.run.final.R, t.result.final.R);
  EXPECT_LE(br.accuracy->err_estimate, tol);
  EXPECT_EQ(br.accuracy->force_evals, t.total_force_evals);
  // The total counts every run of the accuracy mode, the delivered one among them.
  EXPECT_EQ(r.force_evals, t.total_force_evals);
  EXPECT_LT(br.run.force_evals, r.force_evals);
  // One pass: with invariants and samples asked for, the delivered run carries them; nothing is
  // integrated again (the same runs and force evaluations), and the sink sees that run only, from
  // t = 0 to t_end, ending in its final state.
  std::vector<double> times;
  State last;
  const SampleSink sink = [&](const Sample& x) {
    times.push_back(x.t);
    last = x.s;
  };
  Options observed;
  observed.sink = &sink;
  const Result with = integrate(s, "auto", Accuracy{tol, t_end}, observed);
  ASSERT_EQ(with.outcome, Outcome::ok) << with.reason;
  const BodyResult& wb = with.bodies.front();
  ASSERT_TRUE(wb.run.invariants.has_value());
  EXPECT_EQ(wb.run.final.R, br.run.final.R);
  EXPECT_EQ(wb.accuracy->runs, br.accuracy->runs);
  EXPECT_EQ(with.force_evals, r.force_evals);
  ASSERT_EQ(static_cast<long>(times.size()), wb.run.steps + 1);
  EXPECT_TRUE(std::is_sorted(times.begin(), times.end()));
  EXPECT_EQ(times.front(), 0.0);
  EXPECT_EQ(last.R, wb.run.final.R);
}

TEST(Api, OutcomesAreTyped) {
  // refused: ks is for a material point; the reason is the method's own.
  const Scene s = thesis();
  const Result refused = integrate(s, "ks", FictitiousSteps{0.1, EndTime{1.0}});
  EXPECT_EQ(refused.outcome, Outcome::refused);
  EXPECT_EQ(refused.bodies.front().reason, refusal(method_or_throw("ks"), s.bodies.front(), s.centres));
  EXPECT_NE(refused.reason.find(refused.bodies.front().reason), std::string::npos);
  // diverged: a step far too large for the encounter of a close pass.
  SceneParams close;
  close.start.Kz = 0.1;
  close.start.d = 0.05;
  close.start.L = 20.0;
  const Result diverged = integrate(thesis_scene(close), "thesis-euler", FixedSteps{0.5, 200});
  EXPECT_EQ(diverged.outcome, Outcome::diverged) << outcome_name(diverged.outcome);
  EXPECT_FALSE(diverged.reason.empty());
  // failed: an accuracy a method cannot reach on the scene (the thesis's Euler is first order for
  // B != 0: 1e-12 would take more than the search's budget of force evaluations).
  const Result failed = integrate(s, "thesis-euler", Accuracy{1e-12, 50.0});
  EXPECT_EQ(failed.outcome, Outcome::failed);
  EXPECT_FALSE(failed.reason.empty());
  EXPECT_EQ(outcome_name(Outcome::collision), "collision");
}

// A spin angle per step measured at the step's end, against |B||K1|/D h computed here: both are
// the same few operations on a K1 that free flight keeps constant.
constexpr double kSpinAngleTol = 1e-13;

TEST(Api, AStepThatCannotFollowTheSpinIsUnresolved) {
  // Free flight (A = 0): K1 is constant, so every step turns the spin by |B||K1|/D h exactly.
  SceneParams free;
  free.A = 0.0;
  const Scene flight = thesis_scene(free);
  const BodyPoint& p = flight.bodies.front().p;
  const double K1 = to_momenta(p, flight.bodies.front().s0).K1.norm();
  const double rate = std::abs(p.B) * K1 / p.D();
  const double h = 1.5 * kMaxSpinAngle / rate;  // one and a half times the largest resolved step
  // The exact splitting's drift turns the spin exactly: in free flight any angle is resolved.
  const Result exact = integrate(flight, "lp-y4", FixedSteps{h, 20});
  ASSERT_TRUE(exact.bodies.front().run.invariants);
  EXPECT_NEAR(exact.bodies.front().run.invariants->max_spin_angle, rate * h, kSpinAngleTol * rate * h);
  EXPECT_EQ(exact.outcome, Outcome::ok) << exact.reason;
  // RK4 cannot follow that rotation: its energy explodes first, and diverged takes precedence.
  EXPECT_EQ(integrate(flight, "rk4", FixedSteps{h, 20}).outcome, Outcome::diverged);
  // In the field of table 3.1 the kicks change K1 between exact rotations: the same spin angle is
  // unresolved though the energy error stays below 1; half the resolved angle is ok.
  const Scene s = thesis();
  const double rate0 = std::abs(p.B) * to_momenta(p, s.bodies.front().s0).K1.norm() / p.D();
  const Result coarse = integrate(s, "lp-y4", FixedSteps{1.5 * kMaxSpinAngle / rate0, 100});
  EXPECT_EQ(coarse.outcome, Outcome::unresolved) << coarse.reason;
  EXPECT_NE(coarse.reason.find("turned the spin"), std::string::npos) << coarse.reason;
  EXPECT_EQ(integrate(s, "lp-y4", FixedSteps{0.5 * kMaxSpinAngle / rate0, 100}).outcome, Outcome::ok);
  // Near D = 0 (issue #24): lp-verlet ended 13467 off in y with an energy error at its floor.
  SceneParams stiff;
  stiff.B = 0.9999999999995;
  const Result near_zero_D = integrate(thesis_scene(stiff), "lp-verlet", FixedSteps{1e-3, 20000});
  EXPECT_EQ(near_zero_D.outcome, Outcome::unresolved) << near_zero_D.reason;
  EXPECT_LT(near_zero_D.bodies.front().run.invariants->max_rel_dE, kDefaultMaxEnergyError)
      << "the energy error cannot see it; the resolution check does";
}

TEST(Api, AStepThatJumpsPastACentreIsUnresolvedUnlessItsStagesFollowTheCentre) {
  SceneParams pass;
  pass.B = 0.0;
  pass.start.d = 3.0;
  const Scene s = thesis_scene(pass);
  const Result rk4 = integrate(s, "rk4", FixedSteps{16.0, 10});
  EXPECT_EQ(rk4.outcome, Outcome::unresolved) << rk4.reason;
  EXPECT_NE(rk4.reason.find("direction to a centre"), std::string::npos) << rk4.reason;
  EXPECT_LT(rk4.bodies.front().run.invariants->min_turn_cos, std::cos(kMaxTurnAngle));
  // The Kepler split solves the motion about the centre in each stage: the same step is exact.
  const Result kepler = integrate(s, "kep-y4", FixedSteps{16.0, 10});
  EXPECT_EQ(kepler.outcome, Outcome::ok) << kepler.reason;
  EXPECT_LT(kepler.bodies.front().run.invariants->min_turn_cos, std::cos(kMaxTurnAngle)) << "it did turn";
}

TEST(Api, TheEnergyBoundIsTheOneStated) {
  const Scene s = thesis();
  // This test is about the energy's bound alone: no error estimate (which would flag the run by itself).
  Options unbounded;
  unbounded.estimate_error = false;
  unbounded.max_energy_error = std::numeric_limits<double>::infinity();
  const FixedSteps steps{1e-4, 500000};
  const Result free_run = integrate(s, "thesis-euler", steps, unbounded);
  ASSERT_EQ(free_run.outcome, Outcome::ok) << free_run.reason;
  const double e = free_run.bodies.front().run.invariants->max_rel_dE;
  ASSERT_GT(e, kDefaultMaxEnergyError) << "the test needs a run beyond the default bound";
  EXPECT_EQ(integrate(s, "thesis-euler", steps).outcome, Outcome::inaccurate);
  Options below = unbounded, above = unbounded;
  below.max_energy_error = 0.5 * e;
  above.max_energy_error = 2.0 * e;
  const Result flagged = integrate(s, "thesis-euler", steps, below);
  EXPECT_EQ(flagged.outcome, Outcome::inaccurate);
  EXPECT_NE(flagged.reason.find("above the bound"), std::string::npos) << flagged.reason;
  EXPECT_EQ(integrate(s, "thesis-euler", steps, above).outcome, Outcome::ok);
  Options invalid;
  invalid.max_energy_error = std::nan("");
  EXPECT_THROW(integrate(s, "thesis-euler", FixedSteps{1e-4, 10}, invalid), Error);
  // Under the thesis code's force law E is not an integral: its drift is not held against any bound.
  Scene code = s;
  for (Centre& k : code.centres) k.law = ForceLaw::thesis_code;
  Options energy_alone;  // its error estimate (0.87 at this step) would flag it by itself
  energy_alone.estimate_error = false;
  const Result published = integrate(code, "thesis-verlet", FixedSteps{1e-3, 50000}, energy_alone);
  EXPECT_EQ(published.outcome, Outcome::ok) << published.reason;
  EXPECT_GT(published.bodies.front().run.invariants->max_rel_dE, kDefaultMaxEnergyError);
}

// Backwards in time (h < 0, a negative end time) is the time-reversed forward run, reversed back: for
// every kind of method, the same numbers with v and w negated, and the same estimate.
TEST(Api, ARunBackwardsIsTheTimeReversedRunForEveryKind) {
  const Scene s = thesis();
  Scene reversed = s;
  reversed.bodies[0].s0 = time_reversed(s.bodies[0].s0);
  const std::vector<std::tuple<std::string, Advance, Advance>> cases = {
      {"lp-y4", FixedSteps{-0.01, 500}, FixedSteps{0.01, 500}},
      {"logh-kl6", FictitiousSteps{0.05, EndTime{-5.0}}, FictitiousSteps{0.05, EndTime{5.0}}},
      {"logh-kl6", FictitiousSteps{-0.05, StepCount{100}}, FictitiousSteps{0.05, StepCount{100}}},
      {"odeint-dopri5", ControlledSteps{1e-3, -5.0, 1e-9}, ControlledSteps{1e-3, 5.0, 1e-9}},
      {"lp-y4", Accuracy{1e-8, -5.0}, Accuracy{1e-8, 5.0}},
  };
  for (const auto& [m, back, forth] : cases) {
    EXPECT_TRUE(is_backward(back)) << m;
    const BodyResult b = integrate(s, m, back).bodies[0], f = integrate(reversed, m, forth).bodies[0];
    ASSERT_EQ(b.outcome, Outcome::ok) << m << ": " << b.reason;
    EXPECT_EQ(b.run.final.R, f.run.final.R) << m;
    EXPECT_EQ(b.run.final.v, (-f.run.final.v).eval()) << m;
    EXPECT_EQ(b.run.t_end, -f.run.t_end) << m;
    EXPECT_LT(b.run.t_end, 0.0) << m;
    EXPECT_TRUE(b.error.value == f.error.value || (std::isnan(b.error.value) && std::isnan(f.error.value)))
        << m << ": " << b.error.value << " against " << f.error.value;
  }
}

TEST(Api, InvalidRequestsThrowWithTheQuantityNamed) {
  const Scene s = thesis();
  EXPECT_THROW(integrate(s, "no-such-method", FixedSteps{1e-2, 10}), Error);
  EXPECT_THROW(integrate(s, "auto", FixedSteps{1e-2, 10}), Error);
  EXPECT_THROW(integrate(s, nullptr, FixedSteps{1e-2, 10}), Error);
  EXPECT_THROW(integrate(s, "lp-y4", FixedSteps{std::nan(""), 10}), Error);
  EXPECT_THROW(integrate(s, "lp-y4", Accuracy{0.0, 10.0}), Error);
  EXPECT_THROW(integrate(s, "lp-y4", Accuracy{1e-6, 0.0}), Error);
  EXPECT_THROW(integrate(s, "logh-y4", FictitiousSteps{-0.1, EndTime{1.0}}), Error);  // ds < 0 to a time: no sense
  // An Advance the method does not take.
  EXPECT_THROW(check_takes(method_or_throw("lp-y4"), ControlledSteps{1e-3, 1.0, 1e-8}), Error);
  EXPECT_THROW(check_takes(method_or_throw("odeint-dopri5"), FixedSteps{1e-3, 10}), Error);
  EXPECT_THROW(check_takes(method_or_throw("logh-y4"), FixedSteps{1e-3, 10}), Error);
  EXPECT_THROW(check_takes(method_or_throw("lp-y4"), FictitiousSteps{0.1, EndTime{1.0}}), Error);
  // A scene that breaks a rule: D = m J - B^2 <= 0.
  SceneParams singular;
  singular.B = 1.0;
  EXPECT_THROW(integrate(thesis_scene(singular), "lp-y4", FixedSteps{1e-2, 10}), Error);
  // The library's reasons name quantities (h, tol, every), never a command-line flag.
  Options every0;
  every0.every = 0;
  const std::vector<std::function<void()>> bad = {
      [&] { integrate(s, "lp-y4", FixedSteps{0.0, 10}); },
      [&] { integrate(s, "lp-y4", FixedSteps{1e-2, 10}, every0); },
      [&] { integrate(s, "odeint-dopri5", ControlledSteps{1e-3, 1.0, 1e-20}); },
      [&] { integrate(s, "lp-y4", Accuracy{1e-20, 1.0}); },
      [&] { integrate(s, "lp-y4", Accuracy{2.0, 1.0}); },
      [&] { integrate(s, "logh-y4", FictitiousSteps{0.1, EndTime{1.0}, -1.0}); },
      [&] { integrate(s, "logh-y4", FictitiousSteps{0.1, EndTime{1.0}, 0.0, 0}); },    // a step taken as no steps
      [&] { integrate(s, "logh-y4", FictitiousSteps{0.1, EndTime{1.0}, 0.1, 2}); },    // grouped, with output times
  };
  for (std::size_t i = 0; i < bad.size(); ++i) {
    try {
      bad[i]();
      ADD_FAILURE() << "request " << i << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << "a library error names a flag: " << e.what();
    }
  }
  const Result unreachable = integrate(s, "thesis-euler", Accuracy{1e-12, 50.0});
  EXPECT_EQ(unreachable.reason.find("--"), std::string::npos) << unreachable.reason;
}

TEST(Api, FixedStepsLandOnTheEndTime) {
  const FixedSteps f = fixed_steps_to(1.0, 0.3);
  EXPECT_EQ(f.steps, 4);
  EXPECT_DOUBLE_EQ(f.h * static_cast<double>(f.steps), 1.0);
  EXPECT_EQ(fixed_steps_to(1.0, 0.1).steps, 10);  // 1/0.1 rounds to 10.000000000000002: still 10
  EXPECT_THROW(fixed_steps_to(1.0, 0.0), Error);
  EXPECT_THROW(fixed_steps_to(1e20, 1e-10), Error);
}

TEST(Api, AStepperContinuesAsOneRunOfTheSameSteps) {
  const Scene s = thesis();
  const Body& b = s.bodies.front();
  const double h = 1e-2;
  Stepper stepper("lp-y4", b, s.centres, h);
  for (int k = 1; k <= 10; ++k) ASSERT_EQ(stepper.advance_to(k), Outcome::ok) << stepper.reason();
  EXPECT_EQ(stepper.time(), 10.0);
  EXPECT_EQ(stepper.steps(), 1000);
  const Result one = integrate(s, "lp-y4", FixedSteps{h, 1000});
  const State& whole = one.bodies.front().run.final;
  EXPECT_LT(rel(stepper.state().R, whole.R), kSegmentRoundOff);
  EXPECT_LT(rel(stepper.state().v, whole.v), kSegmentRoundOff);
  EXPECT_LT(rel(stepper.state().w, whole.w), kSegmentRoundOff);
  // The same steps: the same work.
  EXPECT_EQ(stepper.force_evals(), one.bodies.front().run.force_evals);
}

/// logh-pefrl at ds = 0.003 over t = 25 on a close pass: one run is 2.3e-10 from the reference, and its
/// segments land with partial steps of the same scheme; 7 segments agree with it far below its own error
/// (they were 3.7e-8 apart when each segment set logH's g = E - T afresh on its start's energy).
constexpr double kSegmentsOnTheRunsShell = 2e-11;

/// A close pass with a fast spin (B = 0.9, d = 4, L = 40, Kx = 3): where segments and their estimate were measured.
Scene spinning_pass() {
  SceneParams p;
  p.B = 0.9;
  p.start.d = 4.0;
  p.start.L = 40.0;
  p.start.Kx = 3.0;
  return thesis_scene(p);
}

TEST(Api, ATimeTransformedSteppersSegmentsGoOnAsOneRun) {
  const Scene s = spinning_pass();
  for (const char* method : {"logh-pefrl", "ttl-pefrl"}) {
    Stepper one(method, s.bodies.front(), s.centres, 0.003), seven(method, s.bodies.front(), s.centres, 0.003);
    ASSERT_EQ(one.advance_to(25.0), Outcome::ok) << one.reason();
    for (int k = 1; k <= 7; ++k) ASSERT_EQ(seven.advance_to(25.0 * k / 7.0), Outcome::ok) << seven.reason();
    EXPECT_LT(rel(seven.state().R, one.state().R), kSegmentsOnTheRunsShell) << method;
    EXPECT_LT(rel(seven.state().v, one.state().v), kSegmentsOnTheRunsShell) << method;
  }
}

/// The estimate of the search made again after a write covers the run from the state written (measured: error
/// 3.06e-11 in v for 3.04e-11 estimated against lp-kl8 at h = 2.5e-4 from the same state); the bound every
/// estimate is held to: at most 3x low. (What the state carried in is not part of it: the first leg's 4e-11,
/// amplified by the reversed motion to 5.6e-9 at t = 60.)
constexpr double kEstimateAtMostLow = 3.0;

TEST(Api, AStepperWithATolerancePlansAnewAfterAStateIsWritten) {
  // Table 3.1: at the closest approach the spin is reversed (w = -w); the step chosen for the old motion
  // turned the new spin by 3.19 rad and the segment ended unresolved.
  const Scene s = thesis();
  const double t1 = 28.4, tol = 1e-10;
  Stepper stepper("auto", s.bodies.front(), s.centres, Accuracy{tol, 60.0});
  ASSERT_EQ(stepper.advance_to(t1), Outcome::ok) << stepper.reason();
  // A small correction (R moved by 1e-6) moves no time scale: the plan and its report stay, no search.
  const AccuracyReport planned = *stepper.accuracy();
  State nudged = stepper.state();
  nudged.R.x() += 1e-6;
  stepper.set_state(nudged);
  ASSERT_TRUE(stepper.accuracy().has_value());
  EXPECT_EQ(stepper.accuracy()->h_chosen, planned.h_chosen);
  EXPECT_EQ(stepper.accuracy()->basis, planned.basis);
  State flipped = stepper.state();
  flipped.w = -flipped.w;
  stepper.set_state(flipped);
  ASSERT_TRUE(stepper.accuracy().has_value());
  EXPECT_NE(stepper.accuracy()->basis.find("searched again from the state set at t = 28.4"), std::string::npos);
  EXPECT_EQ(stepper.accuracy_t_end(), 60.0);
  EXPECT_LE(stepper.accuracy()->err_estimate, tol);
  Stepper fine("lp-kl8", s.bodies.front(), s.centres, 2.5e-4);
  fine.set_state(flipped, t1);
  ASSERT_EQ(stepper.advance_to(60.0), Outcome::ok) << stepper.reason();
  ASSERT_EQ(fine.advance_to(60.0), Outcome::ok) << fine.reason();
  const double err = std::max(rel(stepper.state().R, fine.state().R), rel(stepper.state().v, fine.state().v));
  EXPECT_LT(err, kEstimateAtMostLow * stepper.accuracy()->err_estimate);
}

/// A stepper's estimate is read against lp-kl8 at h = 1e-3 landing on the same times (1e-13 from h = 5e-4 on
/// these scenes): above the rounding level the companion pair read 0.93..1.1 of the error in 240 checks
/// (bench/stepper_chains.py); held here to at most this far either way.
constexpr double kChainEstimateSpread = 3.0;

/// Whether `estimate` reads `error` within kChainEstimateSpread either way.
::testing::AssertionResult reads(double estimate, double error) {
  if (estimate <= kChainEstimateSpread * error && error <= kChainEstimateSpread * estimate) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "estimate " << estimate << " for an error of " << error;
}

double state_error(const State& a, const State& b) { return std::max(rel(a.R, b.R), rel(a.v, b.v)); }

TEST(Api, AStepperCarriesItsErrorThroughSegmentsWritesAndTheWayBack) {
  // Segments: an unseen spinning pass in 25 segments (the search's estimate, reused, was 5.1x low at 50).
  const Scene spin = spinning_pass();
  Stepper cut("auto", spin.bodies.front(), spin.centres, Accuracy{1e-6, 25.0});
  Stepper ref("lp-kl8", spin.bodies.front(), spin.centres, 1e-3);
  for (int k = 1; k <= 25; ++k) {
    ASSERT_EQ(cut.advance_to(k), Outcome::ok) << cut.reason();
    ASSERT_EQ(ref.advance_to(k), Outcome::ok) << ref.reason();
    EXPECT_TRUE(reads(cut.error().value, state_error(cut.state(), ref.state()))) << "t = " << k;
  }
  EXPECT_EQ(cut.accuracy()->err_estimate, cut.error().value);
  EXPECT_GT(cut.error().force_evals, cut.force_evals());  // the companion at h/2 costs about two runs

  // Forwards to 30 and back in one stepper: the return's distance from the start.
  const Scene s = thesis();
  const State start = s.bodies.front().s0;
  Stepper back("rk4", s.bodies.front(), s.centres, Accuracy{1e-8, 30.0});
  ASSERT_EQ(back.advance_to(30.0), Outcome::ok) << back.reason();
  ASSERT_EQ(back.advance_to(0.0), Outcome::ok) << back.reason();
  EXPECT_TRUE(reads(back.error().value, state_error(back.state(), start)));

  // The same chain as two steppers, the first's error carried into the second: read as the one stepper reads it
  // (rk4's way back cancels most of the way out's, 3.6e-11 left of 3e-9 each).
  Stepper out("rk4", s.bodies.front(), s.centres, Accuracy{1e-8, 30.0});
  ASSERT_EQ(out.advance_to(30.0), Outcome::ok) << out.reason();
  Body there = s.bodies.front();
  there.s0 = out.state();
  Stepper home("rk4", there, s.centres, Accuracy{1e-8, -30.0});
  home.carry_error(out.error_state());
  ASSERT_EQ(home.advance_to(-30.0), Outcome::ok) << home.reason();
  EXPECT_TRUE(reads(home.error().value, state_error(home.state(), start)));
  Stepper plain("lp-y4", s.bodies.front(), s.centres, 0.01);
  EXPECT_FALSE(plain.error().known());
  EXPECT_THROW(plain.carry_error(out.error_state()), Error);

  // A write w = -w at the closest approach turns the error the spin carried: the companion turns with it.
  const double t1 = 28.4;
  Stepper flip("auto", s.bodies.front(), s.centres, Accuracy{1e-8, 60.0});
  Stepper truth("lp-kl8", s.bodies.front(), s.centres, 5e-4);
  ASSERT_EQ(flip.advance_to(t1), Outcome::ok) << flip.reason();
  ASSERT_EQ(truth.advance_to(t1), Outcome::ok) << truth.reason();
  flip.apply([](State x) {
    x.w = -x.w;
    return x;
  });
  State reversed = truth.state();
  reversed.w = -reversed.w;
  truth.set_state(reversed);
  ASSERT_EQ(flip.advance_to(60.0), Outcome::ok) << flip.reason();
  ASSERT_EQ(truth.advance_to(60.0), Outcome::ok) << truth.reason();
  EXPECT_TRUE(reads(flip.error().value, state_error(flip.state(), truth.state())));
}

/// A time-transformed stepper's companion takes each of the segment's steps as two, the landing step too, so
/// the pair is Richardson's wherever the segments end: on the scene below it read 1.00x the error in each of
/// 50 segments (0.38-0.60x when the companion ran at ds/2 and a segment shorter than a step was one landing
/// step in both). Held to this either way: the pair's order-4 Richardson at the step auto chose.
constexpr double kShortSegmentSpread = 1.5;

TEST(Api, ATimeTransformedStepperCutShorterThanItsStepReadsItsError) {
  // Two centres of opposite sign, a tilted spin, m and J not 1 (made up for issue #81); ttl-pefrl at tol 1e-6
  // takes steps of 0.27-0.63 over t = 15, read in 50 segments of 0.3.
  Body b;
  b.p = BodyPoint{1.3, 0.4, 0.8};
  b.s0 = State{Vec3(4.0, 2.5, -0.5), Vec3(-0.2, 0.45, 0.1), Vec3(0.3, -0.2, 1.1)};
  const std::vector<Centre> centres{Centre{Vec3::Zero(), 1.5}, Centre{Vec3(7.0, -3.0, 1.0), -0.6}};
  constexpr int kSegments = 50;
  constexpr double kEnd = 15.0;
  Stepper cut("ttl-pefrl", b, centres, Accuracy{1e-6, kEnd});
  Stepper ref("lp-kl8", b, centres, 1e-3);
  for (int k = 1; k <= kSegments; ++k) {
    const double t = kEnd * k / kSegments;
    ASSERT_EQ(cut.advance_to(t), Outcome::ok) << cut.reason();
    ASSERT_EQ(ref.advance_to(t), Outcome::ok) << ref.reason();
    const double err = state_error(cut.state(), ref.state());
    EXPECT_LT(cut.error().value, kShortSegmentSpread * err) << "t = " << t;
    EXPECT_LT(err, kShortSegmentSpread * cut.error().value) << "t = " << t;
  }
  EXPECT_NE(cut.error().basis.find("its landing step too"), std::string::npos) << cut.error().basis;
}

TEST(Api, AStepperHandsOnSamplesWithAbsoluteTimes) {
  const Scene s = thesis();
  std::vector<double> times;
  const SampleSink sink = [&times](const Sample& x) { times.push_back(x.t); };
  Options o;
  o.sink = &sink;
  o.every = 50;
  Stepper stepper("lp-y4", s.bodies.front(), s.centres, 1e-2, o);
  ASSERT_EQ(stepper.advance_to(1.0), Outcome::ok);
  ASSERT_EQ(stepper.advance_to(2.0), Outcome::ok);
  // 0, 0.5, 1 from the first segment; 1.5, 2 from the second (its start is the first's end).
  ASSERT_EQ(times.size(), 5u);
  for (std::size_t i = 0; i < times.size(); ++i) EXPECT_NEAR(times[i], 0.5 * static_cast<double>(i), kTimeRoundOff);
}

TEST(Api, AStepperRefusesTimeThatDoesNotAdvanceAndKeepsItsState) {
  const Scene s = thesis();
  Stepper stepper("logh-y4", s.bodies.front(), s.centres, 0.05);
  ASSERT_EQ(stepper.advance_to(1.0), Outcome::ok);
  const State before = stepper.state();
  EXPECT_THROW(stepper.advance_to(1.0), Error);
  EXPECT_THROW(stepper.advance_to(std::nan("")), Error);
  EXPECT_EQ(stepper.state().R, before.R);
  // A method that refuses the scene leaves the stepper where it was.
  Stepper ks("ks", s.bodies.front(), s.centres, 0.05);
  EXPECT_EQ(ks.advance_to(1.0), Outcome::refused);
  EXPECT_EQ(ks.time(), 0.0);
  EXPECT_FALSE(ks.reason().empty());
}

TEST(Api, AStepperIsCheckedOnceAndDoesNotRunOnFromANonFiniteState) {
  // The request is checked in the constructor (issue #54): a bad option throws there, not at a segment.
  const Scene s = thesis();
  Options bad;
  bad.max_energy_error = -1.0;
  EXPECT_THROW(Stepper("lp-y4", s.bodies.front(), s.centres, 0.01, bad), Error);
  // A material point aimed at an attracting centre whose first drift lands on it (simulate's
  // DivergedRunIsAnErrorNotANumber): the segment ends non-finite, and the next is refused with why.
  SceneParams onto;
  onto.A = 5.0;
  onto.B = 0.0;
  onto.start.K1 = 2.0;
  onto.start.L = 1.0;
  onto.start.d = 0.0;
  onto.start.Kz = 0.0;
  onto.start.Kx = 0.0;
  const Scene fall = thesis_scene(onto);
  Stepper stepper("thesis-euler", fall.bodies.front(), fall.centres, 0.5);
  EXPECT_NE(stepper.advance_to(5.0), Outcome::ok);
  ASSERT_FALSE(stepper.state().R.allFinite()) << "the scene no longer gives a non-finite state";
  EXPECT_EQ(stepper.advance_to(10.0), Outcome::refused);
  EXPECT_NE(stepper.reason().find("the stepper's state is not finite"), std::string::npos) << stepper.reason();
}

TEST(Api, EveryFamilyHandsOnStatesAtOutputTimes) {
  // dt_out = 0.3 is no multiple of the step: each output time lies inside a step (issue #23).
  const Scene s = thesis();
  const Body& b = s.bodies.front();
  constexpr double kDtOut = 0.3, kEnd = 2.0;
  const std::vector<std::pair<const char*, Advance>> runs = {
      {"lp-kl8", fixed_steps_to(kEnd, 0.01)},
      {"rk4", fixed_steps_to(kEnd, 0.001)},
      {"odeint-rkf78", ControlledSteps{1e-3, kEnd, 1e-12}},
      {"gsl-rk8pd", ControlledSteps{1e-3, kEnd, 1e-12}},
      {"logh-kl8", FictitiousSteps{0.01, EndTime{kEnd}}},
  };
  for (const auto& [name, plain] : runs) {
    if (!find_method(name)) continue;  // built without GSL
    Advance with = plain;
    std::visit([](auto& a) { a.dt_out = kDtOut; }, with);
    std::vector<std::pair<double, State>> got;
    const SampleSink sink = [&got](const Sample& x) { got.emplace_back(x.t, x.s); };
    Options o;
    o.sink = &sink;
    const Result r = integrate(s, name, with, o);
    ASSERT_EQ(r.outcome, Outcome::ok) << name << ": " << r.reason;
    // t = 0, 0.3, ..., 1.8 and the end.
    ASSERT_EQ(got.size(), 8u) << name;
    for (std::size_t k = 0; k + 1 < got.size(); ++k) {
      EXPECT_EQ(got[k].first, static_cast<double>(k) * kDtOut) << name;
      if (k > 0) {
        EXPECT_LT(rel(got[k].second.R, reference_state(b, s.centres, got[k].first).R), kOutputTimeError)
            << name << " t=" << got[k].first;
      }
    }
    EXPECT_EQ(got.back().first, kEnd) << name;
    // The run itself is the one without output times, to the last bit.
    const Result bare = integrate(s, name, plain, Options{});
    EXPECT_EQ(r.bodies[0].run.final.R, bare.bodies[0].run.final.R) << name;
    EXPECT_EQ(got.back().second.R, bare.bodies[0].run.final.R) << name;
  }
  Advance bad = FixedSteps{0.01, 10, -1.0};
  const SampleSink none = [](const Sample&) {};
  Options o;
  o.sink = &none;
  EXPECT_THROW(integrate(s, "lp-y4", bad, o), Error);
}

TEST(Api, ASinkThatSaysStopEndsTheRunAtThatState) {
  const Scene s = thesis();
  constexpr double kStopAt = 2.0;
  struct Case {
    const char* method;
    Advance how;
  };
  const std::vector<Case> cases = {
      {"lp-y4", FixedSteps{1e-2, 500}},
      {"rk4", FixedSteps{1e-2, 500, 0.25}},  // output times: the sink sees states made between steps
      {"logh-kl6", FictitiousSteps{0.05, EndTime{5.0}}},
      {"logh-kl6", FictitiousSteps{0.05, EndTime{5.0}, 0.5}},
      {"odeint-dopri5", ControlledSteps{1e-3, 5.0, 1e-9}},
  };
  for (const Case& c : cases) {
    std::vector<KeptSample> seen;
    const SampleSink stop = [&seen](const Sample& x) {
      seen.push_back(KeptSample::of(x));
      return x.t >= kStopAt ? Flow::stop : Flow::go;
    };
    Options o;
    o.sink = &stop;
    const Result r = integrate(s, c.method, c.how, o);
    ASSERT_EQ(r.outcome, Outcome::ok) << c.method << ": " << r.reason;
    const RunResult& run = r.bodies.front().run;
    ASSERT_FALSE(seen.empty());
    const KeptSample& last = seen.back();
    EXPECT_GE(last.t, kStopAt) << c.method;
    if (seen.size() > 1) {
      EXPECT_LT(seen[seen.size() - 2].t, kStopAt) << c.method << ": no state after the stop";
    }
    EXPECT_TRUE(run.stopped) << c.method;
    EXPECT_LT(run.t_end, 5.0) << c.method;
    if (output_interval(c.how) > 0.0) continue;  // an output time is not a step's end: the run stops at its step
    EXPECT_EQ(run.t_end, last.t) << c.method;
    EXPECT_EQ(run.final.R, last.s.R) << c.method;
  }
  // A fixed-step run stopped after step k is the run of k steps, bit for bit.
  long stopped_at = 0;
  const SampleSink at_step = [&stopped_at](const Sample& x) {
    stopped_at = x.step;
    return x.step == 123 ? Flow::stop : Flow::go;
  };
  Options o;
  o.sink = &at_step;
  const Result cut = integrate(s, "lp-kl8", FixedSteps{1e-2, 500}, o);
  const Result whole = integrate(s, "lp-kl8", FixedSteps{1e-2, 123});
  EXPECT_EQ(stopped_at, 123);
  EXPECT_EQ(cut.bodies.front().run.final.R, whole.bodies.front().run.final.R);
  EXPECT_EQ(cut.bodies.front().run.steps, 123);
}

/// Each request throws Error with its fragment in the message.
void expect_errors(const std::vector<std::pair<std::function<void()>, std::string>>& requests) {
  for (const auto& [request, fragment] : requests) {
    try {
      request();
      ADD_FAILURE() << "accepted; expected '" << fragment << "'";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  }
}

/// A step request with the fields given (the rest absent).
StepRequest request(std::optional<double> h, std::optional<long> steps = std::nullopt,
                    std::optional<double> t_end = std::nullopt, std::optional<double> tol = std::nullopt) {
  StepRequest r;
  r.h = h;
  r.steps = steps;
  r.t_end = t_end;
  r.tol = tol;
  return r;
}

TEST(Api, AStepRequestMeansWhatTheMethodsKindMakesOfIt) {
  const MethodInfo& fixed = method_or_throw("lp-y4");
  const MethodInfo& transformed = method_or_throw("logh-y4");
  const MethodInfo& controlled = method_or_throw("odeint-dopri5");
  const auto f = std::get<FixedSteps>(advance_for(&fixed, request(0.03, std::nullopt, 1.0)));
  EXPECT_EQ(f.steps, 34);  // ceil(1 / 0.03): the steps of at most h that land on t_end
  EXPECT_DOUBLE_EQ(f.h * 34, 1.0);
  EXPECT_EQ(std::get<FixedSteps>(advance_for(&fixed, request(0.03, 10))).steps, 10);
  StepRequest code = request(1e-3, 10);
  code.code_loop = true;
  EXPECT_EQ(std::get<FixedSteps>(advance_for(&fixed, code)).steps, 9);  // the thesis code's n - 1
  const auto to_time = std::get<FictitiousSteps>(advance_for(&transformed, request(0.1, std::nullopt, 5.0)));
  EXPECT_EQ(to_time.ds, 0.1);
  EXPECT_EQ(to_time.t_end(), 5.0);
  EXPECT_EQ(to_time.steps(), 0);
  const auto counted = std::get<FictitiousSteps>(advance_for(&transformed, request(0.1, 40)));
  EXPECT_EQ(counted.steps(), 40);
  EXPECT_EQ(counted.t_end(), 0.0);
  const auto c = std::get<ControlledSteps>(advance_for(&controlled, request(0.5, std::nullopt, 0.2, 1e-9)));
  EXPECT_EQ(c.h0, 0.2);  // the first trial step stays inside the run
  EXPECT_EQ(c.t_end, 0.2);
  EXPECT_EQ(c.tol, 1e-9);
  EXPECT_EQ(std::get<ControlledSteps>(advance_for(&controlled, request(1e-3, std::nullopt, 2.0))).tol,
            kDefaultStepTolerance);
  const auto a = std::get<Accuracy>(advance_for(nullptr, request(std::nullopt, std::nullopt, 50.0, 1e-8)));
  EXPECT_EQ(a.tol, 1e-8);
  EXPECT_EQ(a.t_end, 50.0);
  EXPECT_TRUE(std::holds_alternative<Accuracy>(advance_for(&fixed, request(std::nullopt, std::nullopt, 5.0, 1e-8))));
  // Each way a request is incomplete or contradicts itself, named.
  const std::vector<std::pair<std::function<void()>, std::string>> bad = {
      {[&] { (void)advance_for(&fixed, request(0.1, 10, 1.0)); }, "not both"},
      {[&] { (void)advance_for(&fixed, request(0.1)); }, "give an end time t_end or a number of steps"},
      {[&] { (void)advance_for(&fixed, request(0.0, 10)); }, "the step h must be a finite number > 0, got 0"},
      {[&] { (void)advance_for(&transformed, request(-1.0, 10)); }, "the fictitious step ds (h) must be"},
      {[&] { (void)advance_for(nullptr, request(0.1, std::nullopt, 5.0, 1e-8)); }, "not h or steps"},
      {[&] { (void)advance_for(nullptr, request(std::nullopt, std::nullopt, std::nullopt, 1e-8)); }, "needs the end time"},
      {[&] { (void)advance_for(nullptr, request(std::nullopt, std::nullopt, 5.0)); }, "needs the accuracy to deliver"},
  };
  expect_errors(bad);
}

TEST(Api, EachQuantityHasOneMessage) {
  const Scene s = thesis();
  const std::vector<std::pair<std::function<void()>, std::string>> bad = {
      {[&] { integrate(s, "lp-y4", FixedSteps{0.0, 10}); }, "the step h must be a finite number > 0, got 0"},
      {[&] { integrate(s, "lp-y4", FixedSteps{0.1, 0}); }, "the number of steps must be a whole number >= 1, got 0"},
      {[&] { integrate(s, "logh-y4", FictitiousSteps{0.1, StepCount{0}}); },
       "the number of fictitious steps must be a whole number >= 1, got 0"},
      {[&] { integrate(s, "logh-y4", FictitiousSteps{std::nan(""), EndTime{1.0}}); },
       "the fictitious step ds must be a finite number > 0, got nan"},
      {[&] { integrate(s, "logh-y4", FictitiousSteps{0.1, EndTime{std::nan("")}}); }, "the end time t_end must be a finite number > 0"},
      {[&] { integrate(s, "odeint-dopri5", ControlledSteps{1e-3, 1.0, -1.0}); },
       "the tolerance per step tol must be a finite number > 0"},
      {[&] { integrate(s, "lp-y4", FixedSteps{0.1, 10, -1.0}); }, "the output interval dt_out must be a finite number >= 0"},
      {[&] { integrate(s, "lp-y4", Accuracy{1e-8, std::nan("")}); }, "the end time t_end must be a finite number > 0"},
      {[&] { integrate(s, "odeint-dopri5", Accuracy{1e-8, 1.0}); }, "controls its own step"},
      {[&] { integrate(s, "lp-y4", FictitiousSteps{0.1, EndTime{1.0}}); }, "lp-y4 takes FixedSteps"},
  };
  expect_errors(bad);
}

TEST(Api, TheAccuracyModeHandsOnStatesAtOutputTimesForEveryMethod) {
  // Issue #40: with a fixed-step method the accuracy mode handed on the state at t = 0 only.
  const Scene s = thesis();
  constexpr double kDtOut = 0.5, kEnd = 5.0;
  for (const char* name : {"lp-y4", "lp-verlet", "rk4", "kep-y4", "ab4", "logh-y4", "auto"}) {
    std::vector<KeptSample> seen;
    const SampleSink keep = [&seen](const Sample& x) { seen.push_back(KeptSample::of(x)); };
    Options o;
    o.sink = &keep;
    const Result r = integrate(s, name, Accuracy{1e-6, kEnd, kDtOut}, o);
    ASSERT_EQ(r.outcome, Outcome::ok) << name << ": " << r.reason;
    ASSERT_EQ(seen.size(), 11u) << name;
    for (std::size_t k = 0; k < seen.size(); ++k) EXPECT_NEAR(seen[k].t, kDtOut * static_cast<double>(k), kTimeRoundOff) << name;
    EXPECT_EQ(seen.back().s.R, r.bodies.front().run.final.R) << name;
  }
}

TEST(Api, MultiBodyTotalsAreTheSumOfTheBodies) {
  Scene s = thesis();
  Body second = s.bodies.front();
  second.name = "second";
  second.s0.R.y() += 3.0;
  s.bodies.push_back(second);
  const Result r = integrate(s, "lp-y6", FixedSteps{1e-2, 300});
  ASSERT_EQ(r.bodies.size(), 2u);
  EXPECT_EQ(r.force_evals, r.bodies[0].total_force_evals() + r.bodies[1].total_force_evals());
  EXPECT_EQ(r.bodies[0].total_force_evals(), r.bodies[0].run.force_evals + r.bodies[0].error.force_evals);
  EXPECT_NE(r.bodies[0].run.final.R, r.bodies[1].run.final.R);
}

}  // namespace
}  // namespace bodypoint

namespace bodypoint {
namespace {

TEST(ApiSweep, RowsAreTypedAndEqualSingleRuns) {
  SweepSpec s;
  s.axes = {{"d", {5.0, 10.0, 20.0}}, {"B", {0.0, 0.7}}};
  s.methods = {&method_or_throw("lp-y4"), &method_or_throw("ks"), &method_or_throw("logh-y4")};
  s.h = 0.05;
  s.t_end = 5.0;
  const std::vector<SweepRow> rows = run_sweep_rows(s, 1);
  ASSERT_EQ(rows.size(), 18u);
  for (const SweepRow& r : rows) {
    ASSERT_NE(r.method, nullptr);
    const SceneParams p = point_params(s, r.point);
    const Scene scene = thesis_scene(p);
    const std::string why = refusal(*r.method, scene.bodies.front(), scene.centres);
    if (!why.empty()) {  // ks at B = 0.7
      EXPECT_EQ(r.outcome, Outcome::refused) << r.method->name;
      EXPECT_EQ(r.reason, why);
      EXPECT_TRUE(std::isnan(r.result.final.R.x()));
      continue;
    }
    EXPECT_EQ(r.outcome, Outcome::ok) << r.method->name << " " << point_label(s, r.point) << ": " << r.reason;
    const RunResult one = run(*r.method, scene.bodies.front(), scene.centres, point_advance(s, *r.method, r.point));
    EXPECT_EQ(r.result.final.R, one.final.R) << r.method->name << " " << point_label(s, r.point);
    EXPECT_EQ(r.result.force_evals, one.force_evals);
  }
  EXPECT_EQ(rows[1].method->name, "ks");  // task i: point i / M, method i % M
  EXPECT_EQ(rows[3].point, (std::vector<double>{5.0, 0.7}));
  // Threads hand out units in another order; the rows are the same.
  const std::vector<SweepRow> two = run_sweep_rows(s, 2);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(two[i].task, i);
    EXPECT_EQ(two[i].outcome, rows[i].outcome);
    if (rows[i].outcome == Outcome::ok) {
      EXPECT_EQ(two[i].result.final.R, rows[i].result.final.R);
    }
  }
}

TEST(ApiSweep, ABatchsRowsAreIntegratesEstimatesIncluded) {
  // A batch's lanes are estimated by integrate()'s policy, their companions lanes of batches too: every row,
  // its estimate, basis and cost included, is integrate_body's run of its point, bit for bit. The lanes had a
  // copy of the policy, which took one coarse ratio for the whole batch (the smallest its rows' angles
  // allowed): lp-bm4 at h = 0.1 about an attracting centre read 7.3e-11 in a sweep, 2.8e-8 alone.
  struct Case {
    std::vector<Axis> axes;
    double A, J, h, t_end;
  };
  const std::vector<Case> cases = {{{{"d", {2.0, 5.0, 10.0}}}, 1.0, 1.0, 0.1, 50.0},
                                   {{{"B", {0.2, 5.0, 10.0}}}, -2.0, 500.0, 1.0, 60.0},
                                   {{{"Kx", {0.0, 3.0, 6.0}}}, -2.0, 1.0, 0.001, 30.0}};
  for (const Case& c : cases) {
    SweepSpec s;
    s.axes = c.axes;
    s.base.A = c.A;
    s.base.J = c.J;
    s.methods = {&method_or_throw("lp-bm4"), &method_or_throw("rk4"), &method_or_throw("lp-euler")};
    s.h = c.h;
    s.t_end = c.t_end;
    const std::vector<SweepRow> rows = run_sweep_rows(s, 1);
    for (const SweepRow& r : rows) {
      const Scene scene = point_scene(s, r.point);
      Options o;
      o.max_energy_error = s.max_energy_error;
      o.max_error = s.max_error;
      const BodyResult one = integrate_body(scene.bodies.front(), scene.centres, r.method, point_advance(s, *r.method, r.point), o);
      const std::string at = r.method->name + " " + point_label(s, r.point);
      EXPECT_EQ(r.outcome, one.outcome) << at;
      EXPECT_EQ(r.result.final.R, one.run.final.R) << at;
      EXPECT_EQ(r.error.value, one.error.value) << at << ": " << r.error.basis << " | " << one.error.basis;
      EXPECT_EQ(r.error.basis, one.error.basis) << at;
      EXPECT_EQ(r.error.force_evals, one.error.force_evals) << at;
    }
  }
}

TEST(ApiSweep, AutoRowsFollowOneMapPlanThatDependsOnTheSweepAlone) {
  // Issue #80 item 2: the pilots (ceil(sqrt(n)) values of an axis of n) are searched as single runs; every other
  // row starts at its nearest pilot's step. Each row delivers TOL against a run far finer, is reproduced by its
  // method at its h_chosen and omega_c, and is the same whichever rows a runner is given (a shard, a journal).
  constexpr double kTol = 1e-7;
  constexpr double kReferenceTol = 1e-10;  // the reference's own error, 1e-3 of TOL, is added to the bound
  SweepSpec s;
  s.axes = {{"d", {5.0, 7.0, 9.0, 11.0, 13.0}}, {"B", {0.5, 0.7, 0.9}}};
  s.methods = sweep_methods_named("auto");
  s.accuracy = kTol;
  s.t_end = 30.0;
  const std::vector<SweepRow> rows = run_sweep_rows(s, 2);
  const MapPlan plan = plan_map(s, 1);
  ASSERT_EQ(plan.pilots.size(), 6u);  // d = 5, 9, 13 (indices 0, 2, 4 of 5) by B = 0.5, 0.9 (0, 2 of 3)
  EXPECT_EQ(plan.pilots.count(0), 1u);
  EXPECT_EQ(plan.pilots.count(14), 1u);
  std::size_t planned = 0;
  for (const SweepRow& r : rows) {
    const std::string at = point_label(s, r.point);
    ASSERT_EQ(r.outcome, Outcome::ok) << at << ": " << r.reason;
    ASSERT_TRUE(r.accuracy.has_value()) << at;
    EXPECT_LE(r.error.value, kTol) << at;
    const Scene scene = thesis_scene(point_params(s, r.point));
    const BodyResult ref = integrate(scene, "auto", Accuracy{kReferenceTol, s.t_end}).bodies.front();
    ASSERT_TRUE(ref.accuracy.has_value()) << at;
    EXPECT_LE(bodypoint::state_distance(r.result.final, ref.run.final), kTol + ref.accuracy->err_estimate) << at;
    if (plan.pilots.count(r.task)) {  // a pilot is the single run's search
      const BodyResult one = integrate(scene, "auto", Accuracy{kTol, s.t_end}).bodies.front();
      EXPECT_EQ(r.result.final.R, one.run.final.R) << at;
      EXPECT_EQ(r.error.basis.find("planned from"), std::string::npos) << at;
      continue;
    }
    planned += r.error.basis.find("planned from") != std::string::npos;
    Options again;
    again.estimate_error = false;
    again.omega_c = r.accuracy->omega_c;
    const Advance step = is_time_transformed(*r.method)
                             ? Advance(FictitiousSteps{r.accuracy->h_chosen, EndTime{s.t_end}})
                             : Advance(FixedSteps{r.accuracy->h_chosen, r.result.steps});
    EXPECT_EQ(integrate(scene, std::string(r.method->name), step, again).bodies.front().run.final.R, r.result.final.R) << at;
  }
  EXPECT_EQ(planned, rows.size() - plan.pilots.size());
  // A runner given the odd tasks alone (a shard, the rest of a journal) makes the same plan and rows.
  std::vector<std::size_t> odd;
  for (std::size_t i = 1; i < rows.size(); i += 2) odd.push_back(i);
  SweepRunner runner;
  std::vector<SweepRow> some;
  runner.on_row = [&some](SweepRow&& r) { some.push_back(std::move(r)); };
  run_sweep_tasks(s, odd, runner);
  ASSERT_EQ(some.size(), odd.size());
  for (const SweepRow& r : some) {
    EXPECT_EQ(r.result.final.R, rows[r.task].result.final.R) << point_label(s, r.point);
    EXPECT_EQ(r.accuracy->force_evals, rows[r.task].accuracy->force_evals) << point_label(s, r.point);
  }
}

TEST(ApiSweep, APlannedRowFarBelowItsTargetIsJudgedByACoarserRunAndDeliversItsCompanion) {
  // Issue #80 item 2: far passes of a spinning body (d = 84, L = 200) cost what the far field's spin-limited steps
  // cost at any step, so a planned pair far below its target was searched again at a coarser step for as much
  // again (11,016 evaluations for a delivered run of 3,195 at B = 0.65). A third run at twice the companion's
  // step, with the pair's constant c, shows the method's order; the pair then bounds its companion's error
  // within TOL, and the companion (half the answer's cost) is delivered: the rows had read 1e-12 for TOL 1e-9.
  constexpr double kTol = 1e-9;
  // The planned pair (the answer and its companion at 2h) and the third run at 4h, in companions' runs.
  constexpr double kPairAndCoarserRun = 2.0 + 1.0 + 0.5;
  constexpr double kRunsVaryInCost = 0.4;  // a run's cost at the same c is not exactly proportional to 1/h
  // A reference a thousandth of the TOL: the error it leaves is added to the bound.
  constexpr double kReferenceTol = 1e-12;
  constexpr double kEstimateFactor = 3.0;  // the estimates' honesty factor (the accuracy issue's 3)
  SweepSpec s;
  s.base.start.d = 84.37;
  s.axes = {{"B", {0.6, 0.65, 0.706, 0.75, 0.8}}};
  s.methods = sweep_methods_named("auto");
  s.accuracy = kTol;
  s.t_end = 50.0;
  const std::vector<SweepRow> rows = run_sweep_rows(s, 2);
  const MapPlan plan = plan_map(s, 1);
  std::size_t held = 0;
  for (const SweepRow& r : rows) {
    const std::string at = point_label(s, r.point);
    ASSERT_EQ(r.outcome, Outcome::ok) << at << ": " << r.reason;
    ASSERT_TRUE(r.accuracy.has_value()) << at;
    if (plan.pilots.count(r.task)) continue;
    ASSERT_NE(r.error.basis.find("planned from"), std::string::npos) << at;
    EXPECT_LE(r.error.value, kTol) << at;
    EXPECT_GE(r.error.value, kTol / 100.0) << at << ": the companion is delivered, not the answer far below TOL";
    EXPECT_LE(static_cast<double>(r.accuracy->force_evals),
              (kPairAndCoarserRun + kRunsVaryInCost) * static_cast<double>(r.result.force_evals))
        << at;
    const Scene scene = thesis_scene(point_params(s, r.point));
    const BodyResult ref = integrate(scene, "lp-kl8", Accuracy{kReferenceTol, s.t_end}).bodies.front();
    ASSERT_TRUE(ref.accuracy.has_value()) << at;
    const double err = bodypoint::state_distance(r.result.final, ref.run.final);
    EXPECT_LE(err, kTol) << at;
    EXPECT_GE(r.error.value + ref.accuracy->err_estimate, err / kEstimateFactor) << at;
    ++held;
  }
  EXPECT_EQ(held, rows.size() - plan.pilots.size());
}

TEST(ApiSweep, AutoRowsAreTheAccuracyModesSingleRuns) {
  // auto in a sweep (issue #80 item 1): each row is integrate()'s auto at the sweep's accuracy, the method it
  // chose named in the row, a named method beside it unchanged; listed alone without an accuracy, auto
  // delivers the tolerance tol to h x steps.
  SweepSpec s;
  s.axes = {{"d", {5.0, 20.0}}, {"B", {0.0, 0.7}}};
  s.methods = sweep_methods_named("auto,lp-y4");
  ASSERT_EQ(s.methods.front(), nullptr);
  s.accuracy = 1e-8;
  s.t_end = 20.0;
  const std::vector<SweepRow> rows = run_sweep_rows(s, 2);
  ASSERT_EQ(rows.size(), 8u);
  for (const SweepRow& r : rows) {
    const Scene scene = thesis_scene(point_params(s, r.point));
    const Result one = integrate(scene, r.automatic ? "auto" : "lp-y4", Accuracy{1e-8, 20.0});
    const BodyResult& b = one.bodies.front();
    ASSERT_EQ(r.outcome, Outcome::ok) << point_label(s, r.point) << ": " << r.reason;
    ASSERT_NE(r.method, nullptr);
    EXPECT_EQ(r.method, b.method) << point_label(s, r.point);
    EXPECT_EQ(r.result.final.R, b.run.final.R) << point_label(s, r.point);
    EXPECT_LE(r.error.value, 1e-8);
  }
  EXPECT_TRUE(rows[0].automatic);
  EXPECT_FALSE(rows[1].automatic);
  SweepSpec alone;
  alone.axes = {{"d", {5.0}}};
  alone.methods = sweep_methods_named("auto");
  alone.steps = 1000;
  alone.h = 0.02;
  settle_auto(alone);
  ASSERT_EQ(alone.accuracy, std::optional<double>(alone.tol));
  EXPECT_EQ(alone.t_end, 20.0);
  EXPECT_LE(run_sweep_rows(alone, 1).front().error.value, alone.tol);
  SweepSpec mixed = s;
  mixed.accuracy.reset();
  EXPECT_THROW(settle_auto(mixed), Error);
  EXPECT_THROW(run_sweep_rows(mixed, 1), Error);  // a nullptr method without the accuracy mode
}

TEST(ApiSweep, AnInvalidPointIsNamed) {
  SweepSpec s;
  s.axes = {{"B", {0.5, 1.5}}};
  s.methods = {&method_or_throw("lp-y4")};
  s.steps = 10;
  try {
    run_sweep_rows(s);
    FAIL() << "D <= 0 accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("B = 1.5: ", 0), 0u) << e.what();
  }
  s.axes = {{"h", {0.1, -1.0}}};
  EXPECT_THROW(run_sweep_rows(s), Error);
  // NaN means "not given" among the asymptotic data: as a value it would run the scene at d = 10.
  for (const char* datum : {"b", "v_inf"}) {
    s.axes = {{datum, {1.0, std::nan("")}}};
    EXPECT_THROW(run_sweep_rows(s), Error) << datum;
  }
  s.axes = {{"L", {100.0, std::numeric_limits<double>::infinity()}}};
  EXPECT_THROW(run_sweep_rows(s), Error);
  s.axes.clear();
  EXPECT_THROW(run_sweep_rows(s), Error);
}

}  // namespace
}  // namespace bodypoint

namespace bodypoint {
namespace {

TEST(ApiCatalogue, AnUnknownMethodSuggestsTheClosestName) {
  const auto message = [](std::string_view name) {
    try {
      method_or_throw(name);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  for (const auto& [typo, near] : {std::pair{"RK4", "rk4"}, {"lp-y5", "lp-y4"}, {"logh-kl7", "logh-kl6"}, {"lp-pefr", "lp-pefrl"}})
    EXPECT_EQ(message(typo).rfind("unknown method '" + std::string(typo) + "' (did you mean '" + near + "'?); valid: rk4, ", 0), 0u)
        << message(typo);
  const std::string far = message("runge-kutta");
  EXPECT_EQ(far.find("did you mean"), std::string::npos) << far;
  for (const MethodInfo& m : methods()) EXPECT_NE(far.find(m.name), std::string::npos) << m.name << " not listed";
}

}  // namespace
}  // namespace bodypoint
