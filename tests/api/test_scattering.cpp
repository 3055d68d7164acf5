// Events and the observables of an encounter (bodypoint.hpp Event, scattering.hpp) through the library:
// closest approaches, radii and planes located on every family's own steps against Kepler's analytic
// values, the asymptotic deflection against Rutherford's formula, and the guiding-centre asymptotes of a
// spinning body converging with distance.
#include "bodypoint/bodypoint.hpp"
#include "bodypoint/detail/model_parts.hpp"
#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/reference.hpp"
#include "common.hpp"
#include "encounter_parts.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace bodypoint {
namespace {

/// Issue #22's target for r_min and t_min against Kepler's values: every method below runs at a step
/// whose global error is ~1e-14 over this short pass, and the root finder locates t to a few ulps.
constexpr double kKeplerRel = 1e-12;
/// A radius or plane located on the steps: g = 0 to round-off of the state (distances of order 5).
constexpr double kEventRoundOff = 1e-13;
/// Issue #22: the asymptotic deflection of a material point agrees with Rutherford's to 1e-10.
constexpr double kRutherfordRel = 1e-10;
/// d_for_impact_parameter solves d to round-off; b = |d - Kz/K1| (B = 0, d ~ 1 + b) is then known to a
/// few ulps of d, not of b: at b = 1e-3 that is ~1e-13 of b.
constexpr double kImpactUlps = 8.0;

/// The time delay of a material point's run at tol 1e-12 over t ~ 100: the run's time is exact, its
/// position ~1e-12 relative at r ~ 200 (2e-10), i.e. ~1e-10 in time at v ~ 5; the Kepler legs' times
/// are evaluated to round-off of t.
constexpr double kDelayAbs = 1e-9;

/// A material point passing a repelling (A = -2) or attracting (A = 2) centre at b ~ 1 from L = 20.
Scene kepler_scene(double A) {
  SceneParams p;
  p.A = A;
  p.B = 0.0;
  p.start.d = 2.0;
  p.start.L = 20.0;
  return thesis_scene(p);
}

struct Case {
  const char* method;
  Advance how;
};

std::vector<Case> every_family() {
  std::vector<Case> c = {
      {"lp-y8", FixedSteps{2e-3, 4000}},                       // exact Lie-Poisson, fixed step
      {"thesis-y6", FixedSteps{1e-3, 8000}},                   // the thesis's drift/kick
      {"rk4", FixedSteps{1e-3, 8000}},                         // Boost.Odeint fixed step
      {"logh-kl8", FictitiousSteps{0.02, EndTime{8.0}}},        // time-transformed
      {"ks", FictitiousSteps{0.01, EndTime{8.0}}},              // regularised
      {"odeint-rkf78", ControlledSteps{1e-3, 8.0, 1e-14}},     // step-size control
      {"lp-kl8", Accuracy{1e-12, 8.0}},                        // the accuracy mode
  };
  if (find_method("gsl-rk8pd")) c.push_back({"gsl-rk8pd", ControlledSteps{1e-3, 8.0, 1e-14}});
  return c;
}

TEST(Events, ClosestApproachRadiusAndPlaneOnEveryFamilyAgainstKepler) {
  const Scene s = kepler_scene(-2.0);
  const Body& b = s.bodies.front();
  const auto peri = kepler_periapsis(b.p.m, -s.centres.front().A, b.s0.R, to_momenta(b.p, b.s0).K1);
  ASSERT_TRUE(peri.has_value());
  Options o;
  o.events = {Event{}, Event{Event::Kind::radius, 0, 5.0, Vec3::UnitX()}, Event{Event::Kind::plane, 0, 0.0, Vec3::UnitX()}};
  for (const Case& c : every_family()) {
    const Result r = integrate(s, c.method, c.how, o);
    ASSERT_EQ(r.outcome, Outcome::ok) << c.method << ": " << r.reason;
    const std::vector<EventHit>& hits = r.bodies.front().events;
    // in time order: r = 5 inbound, closest, x = 0, r = 5 outbound
    ASSERT_EQ(hits.size(), 4u) << c.method;
    EXPECT_EQ(hits[0].event, 1u);
    EXPECT_EQ(hits[1].event, 0u) << c.method;
    EXPECT_EQ(hits[2].event, 2u) << c.method;
    EXPECT_EQ(hits[3].event, 1u);
    EXPECT_NEAR(hits[1].r / peri->r, 1.0, kKeplerRel) << c.method;
    EXPECT_NEAR(hits[1].t / peri->dt, 1.0, kKeplerRel) << c.method;
    EXPECT_NEAR(hits[0].r, 5.0, kEventRoundOff) << c.method;
    EXPECT_NEAR(hits[3].r, 5.0, kEventRoundOff) << c.method;
    EXPECT_NEAR(hits[2].s.R.x(), 0.0, kEventRoundOff) << c.method;
    EXPECT_LT(hits[0].t, hits[1].t);
    EXPECT_GT(r.bodies.front().total_force_evals(), r.bodies.front().run.force_evals - 1) << c.method;
  }
}

TEST(Events, EachHitCarriesAnErrorThatCoversItsDistanceFromKepler) {
  // Issue #81 item 2: a located event's t, r and state carry their errors (the same events on companions at 2h
  // and 4h), or say they have none (NaN). Coarse steps, so that the hits are measurably off Kepler's periapsis.
  constexpr double kLowest = 1.0 / 3.0;  // bench/estimate_ladder.py's bound on an estimate below the error
  const Scene s = kepler_scene(-2.0);
  const Body& b = s.bodies.front();
  const auto peri = kepler_periapsis(b.p.m, -s.centres.front().A, b.s0.R, to_momenta(b.p, b.s0).K1);
  ASSERT_TRUE(peri.has_value());
  Options o;
  o.events = {Event{}};
  const std::vector<Case> cases = {{"lp-y4", FixedSteps{0.02, 400}},          {"rk4", FixedSteps{0.02, 400}},
                                   {"thesis-y6", FixedSteps{0.02, 400}},      {"logh-kl6", FictitiousSteps{0.3, EndTime{8.0}}},
                                   {"logh-y4", FictitiousSteps{0.1, EndTime{8.0}}}, {"lp-kl8", Accuracy{1e-8, 8.0}}};
  int known = 0;
  for (const Case& c : cases) {
    const BodyResult r = integrate(s, c.method, c.how, o).bodies.front();
    ASSERT_EQ(r.outcome, Outcome::ok) << c.method << ": " << r.reason;
    ASSERT_EQ(r.events.size(), 1u) << c.method;
    const EventHit& h = r.events.front();
    EXPECT_GT(r.event_force_evals, 0) << c.method << ": the companions are the events' cost";
    if (std::isfinite(h.r_error)) {
      ++known;
      EXPECT_GE(h.r_error, kLowest * std::abs(h.r - peri->r)) << c.method;
    }
    if (std::isfinite(h.t_error)) {
      EXPECT_GE(h.t_error, kLowest * std::abs(h.t - peri->dt)) << c.method;
    }
  }
  EXPECT_GE(known, 4) << "most hits have an error";
  // A step-size-controlled peer has no step to scale: its hits say they have none.
  const BodyResult peer = integrate(s, "odeint-rkf78", ControlledSteps{1e-3, 8.0, 1e-10}, o).bodies.front();
  ASSERT_EQ(peer.events.size(), 1u);
  EXPECT_TRUE(std::isnan(peer.events.front().r_error) && std::isnan(peer.events.front().t_error));
}

TEST(Events, AStopAtTheClosestApproachUnderATolerancesStatesItsTimesError) {
  // Issue #81 item 2: stopped at the closest approach under --tol 1e-8, auto's run (logh-pefrl) located it
  // 5.8e-11 off in t, the three runs' times observing no order (the companion at 4h out of its regime): t_error
  // was "not known". Where they observe none, the state's error bounds the time's (g's change over its rate). Against
  // lp-kl8 at h = 0.005, whose closest approach is 2.5e-14 from its own companions'.
  constexpr double kReferenceStep = 0.005;
  const Scene s = thesis_scene(SceneParams{});
  Options o;
  Event closest;
  closest.stop = true;
  Event plane;  // x = 0, crossed near the closest approach
  plane.kind = Event::Kind::plane;
  o.events = {closest, plane};
  const BodyResult fine = integrate(s, "lp-kl8", FixedSteps{kReferenceStep, static_cast<long>(60.0 / kReferenceStep)}, o).bodies.front();
  const BodyResult r = integrate(s, nullptr, Accuracy{1e-8, 60.0}, o).bodies.front();
  ASSERT_EQ(r.outcome, Outcome::ok) << r.reason;
  ASSERT_EQ(r.events.size(), fine.events.size());
  for (std::size_t i = 0; i < r.events.size(); ++i) {
    const EventHit& h = r.events[i];
    const std::string label = o.events[h.event].label();
    // The stop's state is the final state, whose estimate it carries: all three are known there.
    if (o.events[h.event].stop) {
      ASSERT_TRUE(std::isfinite(h.t_error) && std::isfinite(h.r_error)) << label;
    }
    if (std::isfinite(h.t_error)) {
      EXPECT_GE(h.t_error, std::abs(h.t - fine.events[i].t)) << label;
    }
    if (std::isfinite(h.r_error)) {
      EXPECT_GE(h.r_error, std::abs(h.r - fine.events[i].r)) << label;
    }
  }
}

TEST(Events, ClosestApproachToAnAttractingCentre) {
  const Scene s = kepler_scene(2.0);
  const Body& b = s.bodies.front();
  const auto peri = kepler_periapsis(b.p.m, -s.centres.front().A, b.s0.R, to_momenta(b.p, b.s0).K1);
  ASSERT_TRUE(peri.has_value());
  Options o;
  o.events = {Event{}};
  for (const Case& c : {Case{"lp-y8", FixedSteps{5e-4, 16000}}, Case{"odeint-rkf78", ControlledSteps{1e-3, 8.0, 1e-14}}}) {
    const Result r = integrate(s, c.method, c.how, o);
    ASSERT_EQ(r.outcome, Outcome::ok) << c.method << ": " << r.reason;
    ASSERT_EQ(r.bodies.front().events.size(), 1u) << c.method;
    EXPECT_NEAR(r.bodies.front().events[0].r / peri->r, 1.0, kKeplerRel) << c.method;
    EXPECT_NEAR(r.bodies.front().events[0].t / peri->dt, 1.0, kKeplerRel) << c.method;
  }
}

TEST(Events, TheCallersSamplesAreTheSameWithEvents) {
  const Scene s = kepler_scene(-2.0);
  std::vector<double> plain, watched;
  const SampleSink a = [&](const Sample& x) { plain.push_back(x.t); };
  const SampleSink c = [&](const Sample& x) { watched.push_back(x.t); };
  Options o;
  o.every = 7;  // 1000 steps: the last is not a multiple of 7
  o.sink = &a;
  (void)integrate(s, "lp-y4", FixedSteps{8e-3, 1000}, o);
  o.sink = &c;
  o.events = {Event{}};
  const Result r = integrate(s, "lp-y4", FixedSteps{8e-3, 1000}, o);
  EXPECT_EQ(plain, watched);
  EXPECT_EQ(r.bodies.front().events.size(), 1u);
}

TEST(Events, AStepperReportsEventsAtAbsoluteTimes) {
  const Scene s = kepler_scene(-2.0);
  Options o;
  o.events = {Event{}};
  const Result whole = integrate(s, "lp-y8", FixedSteps{2e-3, 4000}, o);
  Stepper st("lp-y8", s.bodies.front(), s.centres, 2e-3, o);
  for (int k = 1; k <= 8; ++k) ASSERT_EQ(st.advance_to(k), Outcome::ok);
  ASSERT_EQ(st.events().size(), 1u);
  ASSERT_EQ(whole.bodies.front().events.size(), 1u);
  EXPECT_NEAR(st.events()[0].t, whole.bodies.front().events[0].t, kKeplerRel);
}

TEST(Events, AStopEventEndsTheRunOnEveryFamily) {
  const Scene s = kepler_scene(-2.0);
  const Event x0{Event::Kind::plane, 0, 0.0, Vec3::UnitX(), false};
  Event stop_x0 = x0;
  stop_x0.stop = true;
  for (const Case& c : every_family()) {
    Options watch;
    watch.events = {Event{}, x0, Event{Event::Kind::radius, 0, 5.0, Vec3::UnitX(), false}};
    const Result whole = integrate(s, c.method, c.how, watch);
    ASSERT_EQ(whole.outcome, Outcome::ok) << c.method << ": " << whole.reason;
    ASSERT_EQ(whole.bodies.front().events.size(), 4u) << c.method;  // r = 5, closest, x = 0, r = 5
    const EventHit& crossing = whole.bodies.front().events[2];
    std::vector<double> times;
    const SampleSink sink = [&](const Sample& x) { times.push_back(x.t); };
    Options cut = watch;
    cut.events[1] = stop_x0;
    cut.sink = &sink;
    const Result r = integrate(s, c.method, c.how, cut);
    ASSERT_EQ(r.outcome, Outcome::ok) << c.method << ": " << r.reason;
    const BodyResult& b = r.bodies.front();
    EXPECT_TRUE(b.run.stopped) << c.method;
    ASSERT_EQ(b.events.size(), 3u) << c.method;  // the outbound r = 5 never happened
    EXPECT_EQ(b.events.back().event, 1u);
    EXPECT_EQ(b.run.t_end, b.events.back().t);
    EXPECT_EQ(b.run.final.R, b.events.back().s.R);
    EXPECT_NEAR(b.run.t_end, crossing.t, kKeplerRel * crossing.t) << c.method;
    EXPECT_NEAR(b.run.final.R.x(), 0.0, kEventRoundOff) << c.method;
    ASSERT_FALSE(times.empty());
    EXPECT_EQ(times.back(), b.run.t_end) << c.method;  // the last sample is the event's state
    EXPECT_LT(*std::max_element(times.begin(), times.end() - 1), b.run.t_end) << c.method;
    if (!b.accuracy) {  // stepping stopped at the crossing, not at t_end
      EXPECT_LT(b.run.steps, whole.bodies.front().run.steps) << c.method;
    }
  }
}

TEST(Events, AStepperStopsAtAStopEventAndContinuesWhenAsked) {
  const Scene s = kepler_scene(-2.0);
  Options o;
  o.events = {Event{Event::Kind::plane, 0, 0.0, Vec3::UnitX(), true}};
  Stepper st("lp-y8", s.bodies.front(), s.centres, 2e-3, o);
  ASSERT_EQ(st.advance_to(8.0), Outcome::ok);
  EXPECT_TRUE(st.stopped());
  ASSERT_EQ(st.events().size(), 1u);
  EXPECT_EQ(st.time(), st.events()[0].t);
  EXPECT_LT(st.time(), 8.0);
  EXPECT_NEAR(st.state().R.x(), 0.0, kEventRoundOff);
  // Continuing from the event's state does not stop on it again.
  ASSERT_EQ(st.advance_to(8.0), Outcome::ok);
  EXPECT_FALSE(st.stopped());
  EXPECT_EQ(st.time(), 8.0);
  EXPECT_EQ(st.events().size(), 1u);
}

TEST(Events, InvalidEventsAreRefusedWithAReason) {
  const Scene s = kepler_scene(-2.0);
  Options o;
  o.events = {Event{Event::Kind::closest_approach, 3, 0.0, Vec3::UnitX()}};
  EXPECT_THROW((void)integrate(s, "lp-y4", FixedSteps{1e-2, 10}, o), Error);
  o.events = {Event{Event::Kind::radius, 0, -1.0, Vec3::UnitX()}};
  EXPECT_THROW((void)integrate(s, "lp-y4", FixedSteps{1e-2, 10}, o), Error);
  o.events = {Event{Event::Kind::plane, 0, 0.0, Vec3::Zero()}};
  EXPECT_THROW((void)integrate(s, "lp-y4", FixedSteps{1e-2, 10}, o), Error);
}

TEST(Scattering, MaterialPointDeflectionIsRutherfordsFromBEqual1em3To1e3) {
  SceneParams p;
  p.B = 0.0;
  for (double b : {1e-3, 1e-1, 1.0, 10.0, 1e3}) {
    p.start.d = d_for_impact_parameter(p, b);
    const Scene s = thesis_scene(p);
    const Body& body = s.bodies.front();
    const double t_end = 2.0 * p.start.L / p.start.K1;  // v_inf ~ K1/m
    const Result r = integrate(s, "lp-kl8", Accuracy{1e-12, t_end});
    ASSERT_EQ(r.outcome, Outcome::ok) << b << ": " << r.reason;
    const Scattering sc = scattering(body.p, s.centres, body.s0, r.bodies.front().run.final);
    ASSERT_EQ(sc.asymptotes, "kepler");
    EXPECT_NEAR(sc.b, b, kImpactUlps * std::numeric_limits<double>::epsilon() * std::max(p.start.d, b)) << b;
    const double rutherford = 2.0 * std::atan(std::abs(p.A) / (p.m * sc.v_inf * sc.v_inf * sc.b));
    EXPECT_NEAR(sc.deflection / rutherford, 1.0, kRutherfordRel) << "b = " << b;
    EXPECT_EQ(sc.out_of_plane, 0.0) << b;  // the plane z = 0 holds the whole orbit
  }
}

TEST(Scattering, MaterialPointTimeDelayIsKeplersAtEveryDistance) {
  // Runs stopped at r = 300 (from L = 200) and at r = 5000 (from L = 4000): the delay is a property
  // of the orbit, -2 kappa/(m v^3)(1 + ln e), whatever the distances the run starts and ends at.
  SceneParams p;
  p.B = 0.0;
  for (double L : {200.0, 4000.0}) {
    p.start.L = L;
    p.start.d = d_for_impact_parameter(p, 0.5);
    const Scene s = thesis_scene(p);
    const Body& body = s.bodies.front();
    Options o;
    o.events = {Event{Event::Kind::radius, 0, 1.25 * L, Vec3::UnitX(), true}};
    const Result r = integrate(s, "ks", FictitiousSteps{0.02, EndTime{4.0 * L / p.start.K1}}, o);
    ASSERT_EQ(r.outcome, Outcome::ok) << r.reason;
    ASSERT_TRUE(r.bodies.front().run.stopped);
    const RunResult& run = r.bodies.front().run;
    const Scattering sc = scattering(body.p, s.centres, body.s0, run.final, run.t_end);
    const double kappa = -p.A, v = sc.v_inf;
    const auto q = kepler_periapsis(body.p.m, kappa, body.s0.R, to_momenta(body.p, body.s0).K1);
    ASSERT_TRUE(q.has_value());
    const double kepler = -2.0 * kappa / (body.p.m * v * v * v) * (1.0 + std::log(q->e));
    EXPECT_NEAR(sc.time_delay, kepler, kDelayAbs) << "L = " << L;
  }
}

TEST(Scattering, GuidingCentreAsymptotesConvergeWithDistance) {
  // One spinning body's pass (thesis table 3.1 with d = 2) seen from the states where it crosses
  // r = 25, 100, 400 and 3200 on the way in and out: the deflection between the guiding-centre
  // asymptotes of each pair approaches the farthest pair's, faster than K1's own turn does.
  const SceneParams p = rounded_pass();
  const Scene s = thesis_scene(p);
  const Body& body = s.bodies.front();
  const std::vector<double> radii = {25.0, 100.0, 400.0, 3200.0};
  Options o;
  o.track_invariants = false;
  for (double r : radii) o.events.push_back(Event{Event::Kind::radius, 0, r, Vec3::UnitX()});
  // The pass amplifies rounding (common.hpp, rounded_pass): TOL above it. 1e-10 was delivered once by a
  // companion at ds/2 sharing the answer's grid (1.2e-10 off, estimated 7.9e-11).
  const Result res = integrate(s, "logh-kl8", Accuracy{kRoundedPassTol, rounded_pass_end(p)}, o);
  ASSERT_EQ(res.outcome, Outcome::ok) << res.reason;
  std::vector<double> theta, turn;
  for (std::size_t k = 0; k < radii.size(); ++k) {
    std::vector<const EventHit*> pair;
    for (const EventHit& h : res.bodies.front().events)
      if (h.event == k) pair.push_back(&h);
    ASSERT_EQ(pair.size(), 2u) << radii[k];
    const Scattering sc = scattering(body.p, s.centres, pair[0]->s, pair[1]->s);
    ASSERT_EQ(sc.asymptotes, "guiding-centre");
    theta.push_back(sc.deflection);
    turn.push_back(sc.K1_turn);
  }
  const double far = theta.back();
  const double e25 = std::abs(theta[0] - far), e100 = std::abs(theta[1] - far), e400 = std::abs(theta[2] - far);
  EXPECT_LT(e100, e25 / 16.0);  // at least as 1/r^2 from 25 to 100
  EXPECT_LT(e400, e100 / 4.0);
  EXPECT_LT(e100, std::abs(turn[1] - far) / 100.0);  // K1's own turn at r = 100 is far from the limit
}

/// A pair of centres seen from far away is their total charge at their centre, up to a quadrupole (the
/// pair's size squared over the distance squared). On one run from L = 800 the deflection between the states
/// where the guiding centre crosses r = 200 both ways is within what an encounter from L = 200 states for it
/// (the asymptotes' model error: against r = 100, over 2^2.7 - 1; kPairSlack for the run's own error) of the
/// deflection between the run's ends.
constexpr double kPairTol = 1e-10;
constexpr double kPairSlack = 1e-9;

TEST(Scattering, SeveralCentresHaveTheirTotalChargesAsymptotes) {
  for (double B : {0.0, 0.7}) {
    Scene s;
    s.centres = {Centre{Vec3(0.0, 0.5, 0.0), -1.0}, Centre{Vec3(0.0, -0.5, 0.0), -1.0}};
    SceneParams p;
    p.B = B;
    p.start.L = 800.0;
    p.start.d = 6.0;
    s.bodies = thesis_scene(p).bodies;
    const Body& body = s.bodies.front();
    ASSERT_EQ(far_field_centre(s.centres)->A, -2.0);
    ASSERT_EQ(far_field_centre(s.centres)->c.norm(), 0.0);
    Options o;
    for (double r : {200.0, 100.0}) {
      Event in{Event::Kind::arrival, 0, r}, out{Event::Kind::departure, 0, r};
      in.about = out.about = Vec3::Zero();
      o.events.push_back(in);
      o.events.push_back(out);
    }
    const EncounterResult e = encounter(body, s.centres, nullptr, kPairTol, Scattering::kNaN, o);
    ASSERT_EQ(e.encounter.outcome, Outcome::ok) << e.encounter.reason;
    EXPECT_NE(e.encounter.scattering.asymptotes.find("total charge"), std::string::npos) << e.encounter.scattering.asymptotes;
    EXPECT_TRUE(std::isfinite(e.encounter.asymptote_error));
    auto between = [&](std::size_t in, std::size_t out) {
      const EventHit *a = nullptr, *b = nullptr;
      for (const EventHit& h : e.run.events) {
        if (h.event == in && !a) a = &h;
        if (h.event == out) b = &h;
      }
      EXPECT_TRUE(a && b);
      return a && b ? scattering(body.p, s.centres, a->s, b->s).deflection : Scattering::kNaN;
    };
    const double at_200 = between(0, 1), at_100 = between(2, 3), at_800 = e.encounter.scattering.deflection;
    const double stated = std::abs(at_200 - at_100) / (std::pow(2.0, kAsymptoteFall) - 1.0) + kPairSlack;
    EXPECT_LE(std::abs(at_200 - at_800), stated) << "B = " << B << ": " << at_800 << " " << at_200 << " " << at_100;
  }
}

// --- Issue #42: only finished encounters, the phase, back-scatter, the closest approach ---

/// The numbers are quoted to 4 digits: B = 0.7, b = 1 finished deflection 0.2876 with K1 = 5 at the
/// start; 0.3101 since K1 is the momentum at infinity of a scene given by b (speed_at_infinity_of: v_inf 7.06,
/// was 7.00 at L = 200).
constexpr double kQuotedDigits = 1e-4;
/// The accuracy of the finished encounter there: auto reaches 1e-9 on it (1e-10 is out of its reach, 1.8e-10
/// between its finest runs).
constexpr double kFinishedTol = 1e-9;
/// At a fixed arrival phase the deflection converges as the start moves away (the phase's model error
/// falls as 1/L): from L = 400 to 800 it changes by ~6e-6 (measured), where one helix pitch of L moved
/// it by up to 0.24 before the phase was a parameter.
constexpr double kPhaseFixedChange = 2e-5;
/// A time delay of a spinning body converges: runs of 200 and 1000 time units differ by ~3e-7 (measured).
constexpr double kDelayConverged = 1e-5;

TEST(Encounter, AnUnfinishedEncounterHasNoDeflection) {
  SceneParams p = with_asymptotic_data(SceneParams{}, 1.0, Scattering::kNaN);
  const Scene s = thesis_scene(p);
  const Body& body = s.bodies.front();
  const EncounterResult cut = encounter(body, s.centres, nullptr, 1e-10, 20.0);
  ASSERT_EQ(cut.run.outcome, Outcome::ok) << cut.run.reason;
  EXPECT_EQ(cut.encounter.outcome, Outcome::incomplete);
  EXPECT_NE(cut.encounter.reason.find("did not finish"), std::string::npos);
  EXPECT_TRUE(std::isnan(cut.encounter.scattering.deflection));
  EXPECT_TRUE(std::isnan(cut.encounter.scattering.time_delay));
  const EncounterResult done = encounter(body, s.centres, nullptr, kFinishedTol);  // to the departure
  ASSERT_EQ(done.encounter.outcome, Outcome::ok) << done.encounter.reason;
  EXPECT_NEAR(done.encounter.scattering.deflection, 0.3101, kQuotedDigits);
  EXPECT_TRUE(done.run.run.stopped);
  EXPECT_LT(done.encounter.asymptote_error, 1e-6);
  EXPECT_GT(done.encounter.asymptote_error, 0.0);
}

/// with_asymptotic_data's message, or "" where it solves the data.
std::string thrown_by_solving(const SceneParams& p, double b, double v_inf) {
  try {
    (void)with_asymptotic_data(p, b, v_inf, Scattering::kNaN);
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

TEST(Encounter, AsymptoticDataAreSolvedAsAValueWithTheThrowingFormsAnswer) {
  SceneParams bound;  // an attracting centre slow enough to hold the body: no incoming asymptote
  bound.A = 2.0;
  bound.start.K1 = 0.1;
  bound.start.L = 5.0;
  for (const auto& [p, b, v] : {std::tuple{SceneParams{}, 1.0, Scattering::kNaN}, {SceneParams{}, Scattering::kNaN, 1.0},
                                {SceneParams{}, 2.0, 1.5}, {bound, 1.0, Scattering::kNaN}, {SceneParams{}, -1.0, Scattering::kNaN}}) {
    const Expected<SceneParams> solved = solve_asymptotic_data(p, b, v, Scattering::kNaN);
    const std::string thrown = thrown_by_solving(p, b, v);
    EXPECT_EQ(solved.error(), thrown) << "b = " << b << ", v_inf = " << v;
    if (solved) {
      const SceneParams again = with_asymptotic_data(p, b, v, Scattering::kNaN);
      EXPECT_EQ(solved->start.d, again.start.d);
      EXPECT_EQ(solved->start.K1, again.start.K1);
    }
  }
  EXPECT_FALSE(solve_asymptotic_data(bound, 1.0, Scattering::kNaN, Scattering::kNaN).has_value());
  EXPECT_NE(thrown_by_solving(bound, 1.0, Scattering::kNaN).find("no start distance d gives the impact parameter b = 1"),
            std::string::npos);
}

TEST(Encounter, NoSceneFromTwiceTheStartDistanceLeavesThatPartNotKnownAndSaysWhy) {
  const SceneParams p = with_asymptotic_data(SceneParams{}, 1.0, Scattering::kNaN);
  const Scene s = thesis_scene(p);
  const Body& body = s.bodies.front();
  EncounterResult r = encounter(body, s.centres, nullptr, 1e-8);
  ASSERT_EQ(r.encounter.outcome, Outcome::ok) << r.encounter.reason;
  const long evals = add_start_distance(
      r.encounter, body, [] { return Expected<Scene>::failure("no scene there"); }, 1e-8, r.run.error.value, "");
  EXPECT_EQ(evals, 0);
  EXPECT_TRUE(std::isnan(r.encounter.start_distance_error));
  EXPECT_TRUE(std::isnan(r.encounter.deflection_error));  // its total is not known either
  EXPECT_NE(r.encounter.start_distance_basis.find("not known"), std::string::npos);
  EXPECT_NE(r.encounter.start_distance_basis.find("no scene there"), std::string::npos);
  // The same scene from 2L exists: the part is known.
  EncounterResult known = encounter(body, s.centres, nullptr, 1e-8);
  add_start_distance(known.encounter, body, [&p] { return thesis_scene_twice_as_far(p, 1.0, Scattering::kNaN, Scattering::kNaN); },
                     1e-8, known.run.error.value, "");
  EXPECT_TRUE(std::isfinite(known.encounter.start_distance_error)) << known.encounter.start_distance_basis;
}

TEST(Encounter, TheClosestApproachIsTheGlobalMinimumNotAHelixWiggle) {
  // Table 3.1: the first local minimum of r is a wiggle of the helix (r = 10.76 at t = 27.57), the
  // encounter's minimum is r = 9.055 at t = 28.40 (issue #42).
  const Scene s = thesis_scene(SceneParams{});
  Options o;
  o.track_invariants = false;
  o.events = {Event{Event::Kind::closest_approach}, Event{Event::Kind::local_minimum}};
  const Result r = integrate(s, "lp-kl8", FixedSteps{1e-3, 50000}, o);
  ASSERT_EQ(r.outcome, Outcome::ok) << r.reason;
  const EventHit* closest = nullptr;
  double first_local = -1.0, smallest_local = 1e300;
  for (const EventHit& h : r.bodies.front().events) {
    if (h.event == 0) closest = &h;
    if (h.event == 1 && first_local < 0.0) first_local = h.r;
    if (h.event == 1) smallest_local = std::min(smallest_local, h.r);
  }
  ASSERT_NE(closest, nullptr);
  EXPECT_EQ(closest->r, smallest_local);
  EXPECT_NEAR(closest->r, 9.055, 1e-3);
  EXPECT_GT(first_local, closest->r + 1.0);
  // Stopped there, a run ends at that least distance, under a tolerance too (the run's own steps found it).
  Options stop;
  stop.events = {Event{Event::Kind::closest_approach, 0, 0.0, Vec3::UnitX(), true}};
  stop.track_invariants = false;
  // The run at tol 1e-8 has its state to ~1e-8 relative: r and t (r ~ 9, t ~ 28) agree to 1e-6 absolute.
  constexpr double kStoppedAtClosest = 1e-6;
  for (const auto& [method, how] : {std::pair<const char*, Advance>{"lp-kl8", FixedSteps{1e-3, 60000}},
                                    std::pair<const char*, Advance>{"auto", Accuracy{1e-8, 60.0}}}) {
    const Result at = integrate(s, method, how, stop);
    ASSERT_EQ(at.outcome, Outcome::ok) << method << ": " << at.reason;
    EXPECT_TRUE(at.bodies.front().run.stopped) << method;
    EXPECT_NEAR(at.bodies.front().run.t_end, closest->t, kStoppedAtClosest) << method;
    EXPECT_NEAR(at.bodies.front().run.final.R.norm(), closest->r, kStoppedAtClosest) << method;
  }
}

/// far-ip at h = 0.9 and logh-bs at 1e-8 per step against lp-kl8 at h = 1e-3: the three runs' states agree to
/// ~1e-10 relative over this pass (r_min 9.0546216052 .. 9.0546216060), so the same event is the same to 1e-8.
constexpr double kLongStepEventRel = 1e-8;

TEST(Events, AStepThatHoldsSeveralTurnsOfTheSpinHidesNoEvent) {
  // far-ip's steps turn the spin by 6 rad and logh-bs's macro steps by up to 10: between their ends the helix
  // makes local minima of r and crosses r = 9.5 twice (W9: far-ip reported r_min = 11.12 at t = 29.23, logh-bs
  // 10.76 at 27.57, for 9.0546 at 28.40). Every event the fine run has, they have, at its time and distance.
  const Scene s = thesis_scene(SceneParams{});
  Options o;
  o.track_invariants = false;
  o.events = {Event{Event::Kind::closest_approach}, Event{Event::Kind::local_minimum},
              Event{Event::Kind::radius, 0, 9.5, Vec3::UnitX()}};
  const Result fine = integrate(s, "lp-kl8", FixedSteps{1e-3, 60000}, o);
  ASSERT_EQ(fine.outcome, Outcome::ok) << fine.reason;
  const std::vector<EventHit>& want = fine.bodies.front().events;
  ASSERT_GE(want.size(), 5u);  // the closest approach, minima, and r = 9.5 in and out
  const std::vector<std::pair<const char*, Advance>> runs = {{"far-ip", FixedSteps{60.0 / 66.0, 66}},
                                                             {"logh-bs", ControlledSteps{1e-4, 60.0, 1e-8}}};
  for (const auto& [method, how] : runs) {
    const Result r = integrate(s, method, how, o);
    ASSERT_EQ(r.outcome, Outcome::ok) << method << ": " << r.reason;
    const std::vector<EventHit>& got = r.bodies.front().events;
    ASSERT_EQ(got.size(), want.size()) << method;
    for (std::size_t k = 0; k < want.size(); ++k) {
      EXPECT_EQ(got[k].event, want[k].event) << method << " hit " << k;
      EXPECT_NEAR(got[k].t, want[k].t, kLongStepEventRel * want[k].t) << method << " hit " << k;
      EXPECT_NEAR(got[k].r, want[k].r, kLongStepEventRel * want[k].r) << method << " hit " << k;
    }
  }
}

TEST(Encounter, ABodyThatBackScattersHasItsAsymptote) {
  // Spin along K1 (Kx = 5, Kz = 0), B = 0.7, b = 0.1: the guiding centre drifts back against K1.
  SceneParams p;
  p.start.Kx = 5.0;
  p.start.Kz = 0.0;
  p = with_asymptotic_data(p, 0.1, Scattering::kNaN);
  const Scene s = thesis_scene(p);
  const EncounterResult e = encounter(s.bodies.front(), s.centres, nullptr, 1e-10);
  ASSERT_EQ(e.encounter.outcome, Outcome::ok) << e.encounter.reason;
  EXPECT_EQ(e.encounter.scattering.asymptotes, "guiding-centre");
  // pi - 0.128 with K1 = 5 at the start; pi - 0.1268 with K1 = 5 the momentum at infinity (speed_at_infinity_of).
  EXPECT_NEAR(e.encounter.scattering.deflection, std::numbers::pi - 0.1268, 1e-3);
}

/// The runs' tolerance where the deflection's convergence in L is measured: far below the changes it
/// measures (6e-6 from L = 400 to 800, 0.07-0.29 over the phase), above these encounters' round-off floor
/// (b = 1 at L = 200 and phase 0: runs at finer steps keep differing by ~5e-9).
constexpr double kEncounterTol = 1e-8;

TEST(Encounter, AtAFixedArrivalPhaseTheDeflectionConvergesWithTheStartDistance) {
  auto theta = [](double L, double psi) {
    SceneParams p;
    p.start.L = L;
    p = with_asymptotic_data(p, 1.0, Scattering::kNaN, psi);
    EXPECT_NEAR(arrival_phase(p), psi, 1e-9);
    const Scene s = thesis_scene(p);
    const EncounterResult e = encounter(s.bodies.front(), s.centres, nullptr, kEncounterTol);
    EXPECT_EQ(e.encounter.outcome, Outcome::ok) << e.encounter.reason;
    return e.encounter.scattering.deflection;
  };
  EXPECT_LT(std::abs(theta(400.0, 1.0) - theta(800.0, 1.0)), kPhaseFixedChange);
  // ... while the phase moves it by far more at one distance (issue #42: 0.046 .. 0.288)
  double lo = 10.0, hi = 0.0;
  for (int j = 0; j < 8; ++j) {
    const double t = theta(200.0, 2.0 * std::numbers::pi * j / 8.0);
    lo = std::min(lo, t);
    hi = std::max(hi, t);
  }
  EXPECT_GT(hi - lo, 0.1);
}

/// Differences that fall as 1/L halve when L doubles, faster ones more (4.2 here since the asymptotes take
/// the speed at infinity from the energy and b from K2Q); at least 1.5 is far from what the flawed arrival
/// phase gave below (-0.16: the two differences of opposite signs).
constexpr double kOneOverLMin = 1.5;

TEST(Encounter, NearHeadOnTheArrivalPhaseIsSolvedAndTheDeflectionConvergesInL) {
  // b = 0.0316 at B = 0.5: the guiding centre's model turns K1 about in a time over which G barely moves,
  // where fixed steps of its RK4 put the arrival phase at L = 400 6.2e-3 rad off, and the deflections from
  // L = 200, 400, 800 read 0.1152532, 0.1152485, 0.1152783 (the study's stated error 1.4e-5 missed it).
  auto theta = [](double L) {
    SceneParams p;
    p.B = 0.5;
    p.start.L = L;
    p = with_asymptotic_data(p, 0.031622776601683794, Scattering::kNaN, std::numbers::pi / 2.0);
    const Scene s = thesis_scene(p);
    const EncounterResult e = encounter(s.bodies.front(), s.centres, nullptr, kEncounterTol);
    EXPECT_EQ(e.encounter.outcome, Outcome::ok) << e.encounter.reason;
    return e.encounter.scattering.deflection;
  };
  const double t200 = theta(200.0), t400 = theta(400.0), t800 = theta(800.0);
  const double fall = (t400 - t200) / (t800 - t400);
  EXPECT_GT(fall, kOneOverLMin) << t200 << " " << t400 << " " << t800;
}

// Below that floor the accuracy mode refuses, or delivers within TOL: at 1e-10 a ladder whose middle run sat
// at a zero of the error (logh-kl6 at ds 0.0043 / 0.0023 / 0.0018: differences 4.9e-9, 5.1e-10, 3.6e-9, an
// order of 9.4) was delivered with an estimate of 1.1e-11 for an error of 7.2e-10 (kOrderExcess).
TEST(Encounter, BelowTheRoundOffFloorTheAccuracyModeRefusesOrDelivers) {
  constexpr double kTol = 1e-10;
  SceneParams p;
  p.start.L = 200.0;
  p = with_asymptotic_data(p, 1.0, Scattering::kNaN, 0.0);
  const Scene s = thesis_scene(p);
  const EncounterResult e = encounter(s.bodies.front(), s.centres, nullptr, kTol);
  if (e.encounter.outcome != Outcome::ok) {
    EXPECT_NE(e.encounter.reason.find("out of reach"), std::string::npos) << e.encounter.reason;
    return;
  }
  const State ref = reference_state(s.bodies.front(), s.centres, e.run.run.t_end, 1e-18L);
  EXPECT_LE(bodypoint::state_distance(e.run.run.final, ref), kTol) << "estimate " << e.run.error.value;
}

TEST(Encounter, ASpinningBodysTimeDelayConverges) {
  SceneParams p;
  p.B = 0.9;
  p = with_asymptotic_data(p, 1.0, Scattering::kNaN);
  const Scene s = thesis_scene(p);
  std::vector<double> delay;
  for (double t_end : {200.0, 1000.0}) {
    const EncounterResult e = encounter(s.bodies.front(), s.centres, nullptr, 1e-10, t_end);
    ASSERT_EQ(e.encounter.outcome, Outcome::ok) << e.encounter.reason;
    delay.push_back(e.encounter.scattering.time_delay);
  }
  EXPECT_LT(std::abs(delay[0] - delay[1]), kDelayConverged);
}

TEST(Events, TheLibrarysGrammarParsesEveryFormAndNamesWhatIsWrong) {
  EXPECT_EQ(parse_event("closest").kind, Event::Kind::closest_approach);
  EXPECT_EQ(parse_event("local-min:1").centre, 1u);
  EXPECT_EQ(parse_event("departure").value, 0.0);
  EXPECT_EQ(parse_event("arrival=50").kind, Event::Kind::arrival);
  EXPECT_EQ(parse_event("plane=0,0,2,1").normal, Vec3(0, 0, 2));
  EXPECT_EQ(parse_event("y=3").label(), "y=3");
  for (const char* bad : {"r=abc", "r=5garbage", "r=1e400", "closest:99999999999999999999", "x:1=2", "arrival", "nearest"})
    EXPECT_THROW((void)parse_event(bad), Error) << bad;
}

// --- Issue #79: observables at their L -> infinity limit ---

/// At a fixed (b, v_inf, arrival phase) the deflection from L = 200 and 400 differed by 1.4e-5 while the
/// asymptotes took the speed at infinity from the guiding centre's hyperbola (its mass mu = |K1|/u at the
/// state) and b from G x K1; from the energy and K2Q they differ by 3.6e-9 (B = 0.7, b = 3, v_inf = 7,
/// psi = 1). This bound sits 30x above the new difference and 40x below the old one.
constexpr double kLimitDifference = 1e-7;
/// The solved scene's own asymptote states the data it was solved for, to the secant's 1e-14 and round-off.
constexpr double kDataSolved = 1e-12;

TEST(Encounter, AtFixedAsymptoticDataTheDeflectionHardlyMovesWithTheStartDistance) {
  auto at = [](double L) {
    SceneParams p;
    p.start.L = L;
    p = with_asymptotic_data(p, 3.0, 7.0, 1.0);
    const Scene s = thesis_scene(p);
    const EncounterResult e = encounter(s.bodies.front(), s.centres, nullptr, kEncounterTol);
    EXPECT_EQ(e.encounter.outcome, Outcome::ok) << e.encounter.reason;
    EXPECT_NEAR(e.encounter.scattering.b, 3.0, kDataSolved * 3.0);
    EXPECT_NEAR(e.encounter.scattering.v_inf, 7.0, kDataSolved * 7.0);
    return e.encounter.scattering.deflection;
  };
  EXPECT_LT(std::abs(at(200.0) - at(400.0)), kLimitDifference);
}

TEST(Encounter, AnEncounterGivenByBTakesK1AsItsMomentumAtInfinity) {
  // K1 = 5, Kx = 2, B = 0.7, J = 1, D = 0.51: the guiding centre's speed at momentum 5 is (5 - 1.4)/0.51.
  SceneParams p;
  const double v = speed_at_infinity_of(p);
  EXPECT_DOUBLE_EQ(v, (5.0 - 0.7 * 2.0) / 0.51);
  const Scene s = thesis_scene(with_asymptotic_data(p, 3.0, Scattering::kNaN));
  const Scattering sc = scattering(s.bodies.front().p, s.centres, s.bodies.front().s0, s.bodies.front().s0);
  EXPECT_NEAR(sc.v_inf, v, kDataSolved * v);
  EXPECT_NEAR(sc.in->p_inf, 5.0, kDataSolved * 5.0);
  // A material point's speed at infinity is K1/m; a scene given by d and K1 is a start state and keeps K1.
  p.B = 0.0;
  EXPECT_DOUBLE_EQ(speed_at_infinity_of(p), 5.0);
  EXPECT_EQ(with_asymptotic_data(SceneParams{}, Scattering::kNaN, Scattering::kNaN, 1.0).start.K1, 5.0);
}

/// A spinning body's time delay is its trajectory's, wherever its legs are cut: the same encounter from L = 800 and
/// from its own state where the guiding centre is back in at r = 200 (a long-double reference state; each run cut
/// at its start distance on the way out). While each leg's time to infinity was its state's Kepler hyperbola's
/// (one mass mu = |K1|/u for the whole leg) the two differed by 5.1e-5 (table 3.1, b = 3, arrival phase 1, TOL
/// 1e-10); with the averaged flight to infinity (scattering.cpp, SpinLeg) by 2.5e-7. This bound is 4x above that
/// and 50x below the hyperbola's.
constexpr double kDelayCut = 1e-6;

TEST(Encounter, ASpinningBodysTimeDelayDoesNotDependOnWhereItsLegsAreCut) {
  SceneParams p;
  p.start.L = 800.0;
  p = with_asymptotic_data(p, 3.0, Scattering::kNaN, 1.0);
  const Scene s = thesis_scene(p);
  const Body& body = s.bodies.front();
  const EncounterResult far = encounter(body, s.centres, nullptr, 1e-10);
  ASSERT_EQ(far.encounter.outcome, Outcome::ok) << far.encounter.reason;
  const double t_in = (800.0 - 200.0) / far.encounter.scattering.v_inf;  // G near r = 200 on the way in
  Body near = body;
  near.s0 = reference_state(body, s.centres, t_in, 1e-18L);
  const EncounterResult cut = encounter(near, s.centres, nullptr, 1e-10);
  ASSERT_EQ(cut.encounter.outcome, Outcome::ok) << cut.encounter.reason;
  EXPECT_NEAR(cut.encounter.scattering.time_delay, far.encounter.scattering.time_delay, kDelayCut);
}

/// An accuracy run with a stop event plans for the stop: asked for t_end = 1e5 and stopped at the departure
/// (at t ~ 57), it searched its step over the whole 1e5 (34-164 million evaluations, issue #79); planned for
/// the stop its whole cost is within this factor of the same encounter asked to its default end, two free
/// passes (the search runs to twice the stop's time, about that end; the pilot that finds the stop adds
/// 60 %: 32,013 evaluations against 19,984 on table 3.1, b = 3, TOL 1e-8).
constexpr double kPlannedForTheStop = 2.0;

TEST(Encounter, AnAccuracyRunStoppedByAnEventPlansForTheStopNotTheSpan) {
  const Scene s = thesis_scene(with_asymptotic_data(SceneParams{}, 3.0, Scattering::kNaN, 1.0));
  const Body& body = s.bodies.front();
  Options o = encounter_options(body, s.centres, Options{}, true);
  const BodyResult far = integrate_body(body, s.centres, nullptr, Accuracy{kEncounterTol, 1e5}, o);
  ASSERT_EQ(far.outcome, Outcome::ok) << far.reason;
  ASSERT_TRUE(far.run.stopped);
  const EncounterResult near = encounter(body, s.centres, nullptr, kEncounterTol);
  ASSERT_EQ(near.run.outcome, Outcome::ok) << near.run.reason;
  EXPECT_LT(static_cast<double>(far.total_force_evals()), kPlannedForTheStop * static_cast<double>(near.run.total_force_evals()));
  EXPECT_NEAR(far.run.t_end, near.run.run.t_end, 1e-6 * near.run.run.t_end);
}


// --- Issue #79: a far field crossed by legs of one turn of the spin a step (far_legs.cpp) ---

/// Table 3.1's parameters (with `p`'s changes) given by b = 3 and arrival phase 1, started at L.
Scene arriving_from(double L, SceneParams p = {}) {
  p.start.L = L;
  return thesis_scene(with_asymptotic_data(p, 3.0, Scattering::kNaN, 1.0));
}

/// The reference of an encounter with legs: the same start by logh-kl6 named (no legs; ttl-kl6 about an
/// attracting centre, which logH does not take), at this tol.
constexpr double kLegsReferenceTol = 1e-9;

/// An encounter with legs and its reference without: the deflection within the legs' stated error (the run's
/// orbit and the asymptotes') plus the reference's own.
void expect_legs_meet_their_reference(const Scene& s, double tol) {
  const Body& body = s.bodies.front();
  const EncounterResult legs = encounter(body, s.centres, nullptr, tol);
  ASSERT_EQ(legs.encounter.outcome, Outcome::ok) << legs.encounter.reason;
  EXPECT_NE(legs.run.chosen.find("far legs"), std::string::npos) << legs.run.chosen;
  const bool repelled = std::all_of(s.centres.begin(), s.centres.end(), [](const Centre& c) { return c.A < 0.0; });
  const EncounterResult ref = encounter(body, s.centres, find_method(repelled ? "logh-kl6" : "ttl-kl6"), kLegsReferenceTol);
  ASSERT_EQ(ref.encounter.outcome, Outcome::ok) << ref.encounter.reason;
  EXPECT_EQ(ref.run.chosen.find("far legs"), std::string::npos);
  const double stated = legs.run.error.for_orbit() + legs.encounter.asymptote_error;
  const double ref_error = ref.run.error.value + ref.encounter.asymptote_error;
  const double off = std::abs(legs.encounter.scattering.deflection - ref.encounter.scattering.deflection);
  EXPECT_LE(off, stated + ref_error) << "tol " << tol << ": " << legs.encounter.scattering.deflection << " against "
                                     << ref.encounter.scattering.deflection;
  // The time delay within the legs' run part of its error (theirs and the run's between them) and the reference's.
  const double delay_off = std::abs(legs.encounter.scattering.time_delay - ref.encounter.scattering.time_delay);
  EXPECT_LE(delay_off, legs.encounter.time_delay_run_error + ref.encounter.time_delay_run_error)
      << "tol " << tol << ": " << legs.encounter.scattering.time_delay << " against " << ref.encounter.scattering.time_delay;
  // The closest approach, located on the run between the legs from a hand-off that carries their errors: its
  // distance and time within theirs (the legs' part had been left out, 1e3-2e4x below the distance to the
  // reference: a made-up attracting scene from L = 12,800 at 1e-8, r_min 3.8e-7 off with 8e-11 stated).
  // Where the reference's own location error is not known, its final state's relative error stands for it.
  const Encounter &e = legs.encounter, &f = ref.encounter;
  const auto ref_own = [&](double error, double x) { return std::isfinite(error) ? error : ref.run.error.value * std::abs(x); };
  EXPECT_LE(std::abs(e.r_min - f.r_min), e.r_min_error + ref_own(f.r_min_error, f.r_min))
      << "tol " << tol << ": " << e.r_min << " against " << f.r_min;
  EXPECT_LE(std::abs(e.t_min - f.t_min), e.t_min_error + ref_own(f.t_min_error, f.t_min))
      << "tol " << tol << ": " << e.t_min << " against " << f.t_min;
  // The legs cost a small share of the run without them.
  EXPECT_LT(legs.run.total_force_evals(), ref.run.total_force_evals());
}

TEST(Encounter, AFarStartIsCrossedByLegsWithinTheirStatedError) {
  expect_legs_meet_their_reference(arriving_from(3200.0), 1e-6);
  expect_legs_meet_their_reference(arriving_from(3200.0), 1e-8);
  SceneParams slow;
  slow.B = 0.3;
  slow.start.Kx = 4.0;
  expect_legs_meet_their_reference(arriving_from(1600.0, slow), 1e-6);
}

/// The averaged model's error along the path, in the time delay: Kx = 4, A = -1 (b = 2, arrival phase 0.3) from
/// L = 3200 at TOL 1e-8 had its delay 4.5e-8 off with 1.7e-8 stated while the legs took the state's share of their
/// quiver correction's effect (1/50); new2 below, 4.9e-8 off with 2.8e-8 stated from L = 12,800 at 1e-7.
TEST(Encounter, ALegsTimeDelayIsWithinItsStatedErrorAlongThePath) {
  SceneParams spin;
  spin.A = -1.0;
  spin.start.L = 3200.0;
  spin.start.Kx = 4.0;
  expect_legs_meet_their_reference(thesis_scene(with_asymptotic_data(spin, 2.0, Scattering::kNaN, 0.3)), 1e-8);
  SceneParams attracting;  // made up: an attracting centre, a slower spin
  attracting.A = 1.5;
  attracting.B = 0.8;
  attracting.start.Kz = 3.0;
  attracting.start.L = 12800.0;
  expect_legs_meet_their_reference(thesis_scene(with_asymptotic_data(attracting, 1.5, Scattering::kNaN, 4.0)), 1e-7);
}

TEST(Encounter, LegsCrossTheFarFieldOfSeveralCentres) {
  Scene s = arriving_from(3200.0);
  s.centres = {Centre{Vec3(0.0, 0.5, 0.0), -1.0}, Centre{Vec3(0.0, -0.5, 0.0), -1.0}};
  expect_legs_meet_their_reference(s, 1e-6);
}

/// 16x the start distance adds ln(16)/0.2 steps of the legs (about 14 steps of 36 evaluations, at two steps
/// each, in and out): a few thousand evaluations on the encounter's 10,000-20,000; a run capped by the spin
/// would cost about 16x.
constexpr double kLogGrowth = 1.5;

TEST(Encounter, WithLegsItsCostGrowsLikeTheLogarithmOfTheStartDistance) {
  const auto cost = [](double L) {
    const Scene s = arriving_from(L);
    const EncounterResult e = encounter(s.bodies.front(), s.centres, nullptr, 1e-6);
    EXPECT_EQ(e.encounter.outcome, Outcome::ok) << e.encounter.reason;
    return static_cast<double>(e.run.total_force_evals());
  };
  const double near = cost(3200.0), far = cost(51200.0);
  EXPECT_LT(far, kLogGrowth * near) << near << " -> " << far;
}

/// A time delay's run part is its estimate's pair carried to the delay (ErrorEstimate::quantity). Made-up scenes
/// given by their start states (no limit taken: the trajectory's delay), each at TOL 1e-6 against the same start
/// at kDelayReferenceTol: before, the delay carried the start distance's part alone (from L = 3200 with legs, 7-200x
/// below its distance from a tighter run).
constexpr double kDelayReferenceTol = 1e-10;

TEST(Encounter, ATimeDelayIsWithinItsRunsStatedError) {
  const auto scene = [](double B, double A, double d, double K1, double phase) {
    SceneParams p;
    p.B = B;
    p.A = A;
    p.start.d = d;
    p.start.K1 = K1;
    p.start.phase = phase;
    return thesis_scene(p);
  };
  for (const Scene& s : {scene(0.5, -1.0, 2.0, 5.0, 0.0), scene(0.9, 2.0, 6.0, 3.0, 0.0), scene(0.3, -0.5, 1.0, 5.0, 2.0)}) {
    const Body& body = s.bodies.front();
    const EncounterResult run = encounter(body, s.centres, nullptr, 1e-6);
    const EncounterResult ref = encounter(body, s.centres, nullptr, kDelayReferenceTol);
    ASSERT_EQ(run.encounter.outcome, Outcome::ok) << run.encounter.reason;
    ASSERT_EQ(ref.encounter.outcome, Outcome::ok) << ref.encounter.reason;
    ASSERT_TRUE(std::isfinite(run.encounter.time_delay_run_error));
    EXPECT_LE(std::abs(run.encounter.scattering.time_delay - ref.encounter.scattering.time_delay),
              run.encounter.time_delay_run_error + ref.encounter.time_delay_run_error)
        << "B " << body.p.B << ": " << run.encounter.scattering.time_delay << " against " << ref.encounter.scattering.time_delay;
  }
}

/// The run from twice the start distance has this run's near field (far legs bring both to the same hand-off):
/// its search starts at the step this run delivered (Accuracy::first_step_of), a planned pair where its own
/// search costs 2.6x a run. Table 3.1 from L = 12,800 at TOL 1e-8: 107,433 evaluations from 2L against 162,874
/// for the run from L (0.66) while the run between the legs was searched anew (its TOL is half the encounter's,
/// which the plan had required to be equal), 39,564 (0.24) with the plan; half allows a missed plan's pair more.
constexpr double kTwiceAsFarShare = 0.5;

TEST(Encounter, WithLegsTheRunFromTwiceTheStartDistanceStartsAtTheStepDelivered) {
  constexpr double kTol = 1e-8, kB = 3.0, kPhase = 1.0;
  struct AtLimit {
    Encounter e;
    bool legs;
    double evals, far_evals;
  };
  // Table 3.1 given by (kB, kPhase) from L, its observables taken to the limit as `simulate --scattering` does.
  const auto at_limit = [&](double L) {
    SceneParams p;
    p.start.L = L;
    const SceneParams solved = with_asymptotic_data(p, kB, Scattering::kNaN, kPhase);
    const Scene s = thesis_scene(solved);
    const EncounterResult r = encounter(s.bodies.front(), s.centres, nullptr, kTol);
    EXPECT_EQ(r.encounter.outcome, Outcome::ok) << r.encounter.reason;
    AtLimit a{r.encounter, r.run.chosen.find("far legs") != std::string::npos, static_cast<double>(r.run.total_force_evals()), 0.0};
    a.far_evals = static_cast<double>(add_start_distance(
        a.e, s.bodies.front(), [&] { return thesis_scene_twice_as_far(solved, kB, Scattering::kNaN, kPhase); }, kTol,
        r.run.error.for_orbit(), "", {}, true, &r.run));
    return a;
  };
  const AtLimit far = at_limit(12800.0);
  ASSERT_TRUE(far.legs);
  EXPECT_LT(far.far_evals, kTwiceAsFarShare * far.evals);
  // The plan changes the cost, not the answer's meaning: the limit within the errors stated of the limit from
  // L = 200 (no legs, its run from 2L searched alone).
  const AtLimit near = at_limit(200.0);
  ASSERT_FALSE(near.legs);
  EXPECT_LE(std::abs(far.e.scattering.deflection - near.e.scattering.deflection), far.e.deflection_error + near.e.deflection_error);
}

/// An encounter at the limit and its run from 2L share one run between their far legs, from the hand-off at the
/// limit 2 S(2L) - S(L) (run_pair_with_legs): the limit is the same to first order as from two whole runs, and its
/// run from 2L costs its own legs: 3.5 % and 15 % of the whole on the two scenes below (their legs in from 2L and
/// out beyond L, with companions), where the whole run from 2L it replaces cost 23 % on table 3.1 from L = 12,800
/// (39,564 of 170,605); a quarter tells the two apart.
constexpr double kSharedTwiceShare = 0.25;

/// A scene made up for a test, given by b and arrival phase (Kz the thesis's where not given).
struct MadeUp {
  double A, B, K1, Kx, b, phase;
  double Kz = SceneParams{}.start.Kz;
};
SceneParams made_up_from(const MadeUp& m, double L) {
  SceneParams p;
  p.A = m.A;
  p.B = m.B;
  p.start.K1 = m.K1;
  p.start.Kx = m.Kx;
  p.start.Kz = m.Kz;
  p.start.L = L;
  return with_asymptotic_data(p, m.b, Scattering::kNaN, m.phase);
}

TEST(Encounter, AtTheLimitTheRunsFromLAndTwiceLShareTheRunBetweenTheirLegs) {
  constexpr double kTol = 1e-8;
  // Made up for this test, not the scenes the rule was measured on.
  for (const auto& [m, L] :
       {std::pair{MadeUp{-3.0, 0.6, 5.0, -1.0, 4.0, 2.2}, 3200.0}, std::pair{MadeUp{-0.7, 0.4, 6.0, 2.0, 6.0, 5.5}, 12800.0}}) {
    const SceneParams solved = made_up_from(m, L);
    const Scene s = thesis_scene(solved);
    const Body& body = s.bodies.front();
    // Captured by copy: clang 14 does not implement C++20's capture of structured bindings (P1091).
    const std::function<Expected<Scene>()> far = [&solved, b = m.b, phase = m.phase] {
      return thesis_scene_twice_as_far(solved, b, Scattering::kNaN, phase);
    };
    // Shared, as simulate, sweep, Python and the study run it ...
    std::optional<TwiceAsFar> twice = twice_as_far_beside(far, true, body, s.centres, kTol);
    ASSERT_TRUE(twice);
    EncounterResult shared = encounter_beside(body, s.centres, nullptr, kTol, {}, &*twice);
    ASSERT_EQ(shared.encounter.outcome, Outcome::ok) << shared.encounter.reason;
    ASSERT_TRUE(twice->run) << shared.run.chosen;
    const long twice_evals = add_start_distance(shared.encounter, body, far, kTol, shared.run.error.for_orbit(), "", {}, true,
                                                &shared.run, &*twice);
    // ... and as two whole runs.
    EncounterResult whole = encounter(body, s.centres, nullptr, kTol);
    ASSERT_EQ(whole.encounter.outcome, Outcome::ok) << whole.encounter.reason;
    const long whole_twice_evals = add_start_distance(whole.encounter, body, far, kTol, whole.run.error.for_orbit(), "", {}, true,
                                                      &whole.run);
    const Encounter &a = shared.encounter, &b = whole.encounter;
    EXPECT_LE(std::abs(a.scattering.deflection - b.scattering.deflection), a.deflection_error + b.deflection_error) << L;
    EXPECT_LE(std::abs(a.scattering.out_of_plane - b.scattering.out_of_plane), a.out_of_plane_error + b.out_of_plane_error);
    EXPECT_LE(std::abs(a.scattering.time_delay - b.scattering.time_delay), a.time_delay_error + b.time_delay_error);
    // Every evaluation counted (the legs' too), and the run from 2L is its legs.
    const long shared_evals = shared.run.total_force_evals() + twice_evals;
    EXPECT_LT(shared_evals, whole.run.total_force_evals() + whole_twice_evals);
    EXPECT_LT(static_cast<double>(twice_evals), kSharedTwiceShare * static_cast<double>(shared_evals));
  }
}

/// The closest approach of an encounter given by asymptotic data: its distance within its stated error of the
/// limit's, the trajectories from kClosestReferenceL and twice that by ttl-kl6 named (no legs) at 1e-10, within
/// kStartDistanceFactor (3) times what they differ by. Made up here: an attracting centre, a slow spin. Before, the
/// error was the location's alone (from L = 200 at 1e-8: 9.6e-7 off, 2.2e-11 stated), and the same scene at 1e-6
/// had no start distance part at all: its run from 2L stopped at its departure 1.7e-9 of its distance inside it
/// and read "did not finish".
constexpr double kClosestReferenceL = 3200.0;

TEST(Encounter, AnEncounterAtTheLimitStatesItsClosestApproachWithinItsDistanceFromTheLimit) {
  for (const MadeUp& m : {MadeUp{0.489, 0.525, 3.45, -0.6, 1.43, 1.4, 5.13}, MadeUp{2.364, 0.701, 5.87, 3.0, 5.71, 3.73, 2.57}}) {
    const auto scene_from = [&](double L) { return made_up_from(m, L); };
    const auto closest = [&](double L) {
      const Scene s = thesis_scene(scene_from(L));
      const EncounterResult r = encounter(s.bodies.front(), s.centres, find_method("ttl-kl6"), 1e-10);
      EXPECT_EQ(r.encounter.outcome, Outcome::ok) << r.encounter.reason;
      return r.encounter;
    };
    const Encounter near = closest(kClosestReferenceL), far = closest(2.0 * kClosestReferenceL);
    const double limit_error = 3.0 * (std::abs(near.r_min - far.r_min) + near.r_min_error + far.r_min_error);
    for (const double tol : {1e-6, 1e-8}) {
      const SceneParams solved = scene_from(200.0);
      const Scene s = thesis_scene(solved);
      const Body& body = s.bodies.front();
      EncounterResult e = encounter(body, s.centres, nullptr, tol);
      ASSERT_EQ(e.encounter.outcome, Outcome::ok) << e.encounter.reason;
      add_start_distance(e.encounter, body, [&] { return thesis_scene_twice_as_far(solved, m.b, Scattering::kNaN, m.phase); },
                         tol, e.run.error.for_orbit(), "", {}, true, &e.run);
      EXPECT_TRUE(std::isfinite(e.encounter.deflection_error)) << "A = " << m.A << ": " << e.encounter.start_distance_basis;
      EXPECT_LE(std::abs(e.encounter.r_min - far.r_min), e.encounter.r_min_error + limit_error)
          << "A = " << m.A << ", tol " << tol << ": " << e.encounter.r_min << " against " << far.r_min;
    }
  }
}

TEST(Encounter, LegsLeaveACallersOwnEventsToTheRunWithout) {
  const Scene s = arriving_from(3200.0);
  Options o;
  o.events.push_back(Event{Event::Kind::radius, 0, 100.0});
  const EncounterResult e = encounter(s.bodies.front(), s.centres, nullptr, 1e-6, Scattering::kNaN, o);
  ASSERT_EQ(e.encounter.outcome, Outcome::ok) << e.encounter.reason;
  EXPECT_EQ(e.run.chosen.find("far legs"), std::string::npos);
  EXPECT_TRUE(std::any_of(e.run.events.begin(), e.run.events.end(), [](const EventHit& h) { return h.event == 0; }));
}

}  // namespace
}  // namespace bodypoint
