// --tol and --method auto (adaptive/tolerance.hpp): accuracy only, no timing.
//
// Every run is checked against Boost.Odeint rkf78 in long double at tolerance 1e-18 on scenes the
// step search was not tuned on as well as on the named ones: several centres of both signs, near
// head-on encounters, B = 0 and B != 0, an end time long after the encounter.
#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/bodypoint.hpp"
#include "bodypoint/detail/model_parts.hpp"
#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/scattering.hpp"
#include "bodypoint/scenes.hpp"
#include "cli_helpers.hpp"
#include "common.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace bodypoint {
namespace {

/// The search's runs observe nothing beyond the final state (the accuracy mode's default observers).
const RunOptions kUnobserved = [] {
  RunOptions o;
  o.track_invariants = false;
  return o;
}();

// The estimate is an estimate of the delivered run's error: within this factor of it both ways (the
// accuracy issue's requirement), where the error is measurable.
constexpr double kEstimateFactor = 3.0;
// Below this the "true" error is the reference's own error and the round-off of the run
// (reference rkf78 long double tol 1e-18: 1e-15..1e-14 relative; runs: 1e-15..1e-13), so the
// estimate is compared with the error only above it.
constexpr double kComparableError = 1e-13;
// The whole accuracy mode (pilots, companions, the delivered run) costs at most this many times the
// delivered run in force evaluations. The pilot pair at the coarse step takes a spin-limited far field
// (about 1.5 delivered runs), the answer's companion half of one, a refinement one more: 2.2..3.3 on
// this grid. (The search of the previous revision cost 4..6, plus a repeated run for invariants.)
constexpr double kMaxCostRatio = 3.5;
// About several centres auto's answer is checked against a companion at 1/1.25 of its step (auto_verifies,
// methods.hpp; kVerifyRatio, search/ladder.cpp): 1.25 delivered runs, and a verified search may restart its
// ladder once more (two-centres at 1e-4, Verlet: the pilot pair, two ladders, the companion: 5.07 runs).
constexpr double kVerifyRuns = 2.0;
// Below bodypoint::kProbeBelowTol each run about to be delivered is repeated kProbeRuns times with its
// roundings changed (tolerance.hpp), a delivered run's cost each time; a candidate whose truncation and
// round-off add up to more than tol allows is refined and probed again. On this grid at most this many
// candidates are probed (close at 1e-12: two, 6.9x the delivered run in all).
constexpr int kProbeRounds = 2;
// A refusal for round-off is checked by what it claims: runs of the method at a step far finer than
// tol needs (a quarter of the step that delivered 1e-10), with the step moved by k times this relative
// amount (k = 1..kRoundingTwins), differ from the unmoved run by more than tol/kRefusalMargin at most.
// The shift moves the truncation error by ~1e-9 of itself. One pair's difference is a random draw of
// the amplified round-off (3e-13 and 3e-12 were both seen on one scene), hence the largest of several;
// the margin allows for the refusal having compared the answer's own pair, not these runs.
constexpr double kRoundingShift = 1e-9;
constexpr int kRoundingTwins = 4;
constexpr double kRefusalMargin = 2.0;

struct Case {
  std::string name;
  Scene scene;
  double t_end;
};

Scene from_params(const SceneParams& sp) { return thesis_scene(sp); }

std::vector<Case> cases() {
  std::vector<Case> out;
  out.push_back({"close", named_scene("close").scene, 80.0});
  out.push_back({"two-centres", named_scene("two-centres").scene, 60.0});
  {  // a repelling and an attracting centre, the body passing between them
    Scene s = named_scene("thesis").scene;
    s.centres.push_back({Vec3(30.0, -6.0, 0.0), 1.0});
    validate(s);
    out.push_back({"both-signs", s, 60.0});
  }
  {  // near head-on on a repelling centre: r_min/L ~ 4e-4 (d = 0.02, Kz = 0.05)
    SceneParams sp;
    sp.start.d = 0.02;
    sp.start.Kz = 0.05;
    out.push_back({"head-on", from_params(sp), 80.0});
  }
  {  // a spinning body swinging round an attracting centre
    SceneParams sp;
    sp.A = 2.0;
    sp.start.d = 1.0;
    sp.start.L = 20.0;
    out.push_back({"attracting", from_params(sp), 10.0});
  }
  {  // a material point between two centres (no ks: two centres)
    Scene s = named_scene("two-centres").scene;
    s.bodies.front().p.B = 0.0;
    out.push_back({"material-two-centres", s, 60.0});
  }
  {  // a material point and one centre: ks
    SceneParams sp;
    sp.B = 0.0;
    sp.start.Kz = 0.1;
    sp.start.d = 0.05;
    out.push_back({"material-close", from_params(sp), 80.0});
  }
  {  // long after the encounter
    out.push_back({"close-long", named_scene("close").scene, 400.0});
  }
  return out;
}

/// The largest difference between the run of m at step h and its twins that differ only in rounding
/// (the step moved by k kRoundingShift, k = 1..kRoundingTwins).
double rounding_spread(const MethodInfo& m, const Case& c, double h) {
  const Body& b = c.scene.bodies.front();
  FlatRun spec;
  spec.t_end = c.t_end;
  spec.steps = 0;
  spec.omega_c = bodypoint::automatic_omega_c(b, c.scene.centres, h);
  spec.h = h;
  const State a = run(m, b, c.scene.centres, spec).final;
  double spread = 0.0;
  for (int k = 1; k <= kRoundingTwins; ++k) {
    spec.h = h * (1.0 - k * kRoundingShift);
    spread = std::max(spread, bodypoint::state_distance(a, run(m, b, c.scene.centres, spec).final));
  }
  return spread;
}

TEST(Tolerance, AutoDeliversTolWithAnHonestEstimate) {
  int runs = 0, within_decade = 0, refused = 0;
  double worst_cost = 0.0;
  for (const Case& c : cases()) {
    const Body& b = c.scene.bodies.front();
    const State ref = reference_state(b, c.scene.centres, c.t_end, 1e-18L);
    double coarser_h = 0.0;  // the step of the previous (looser) tolerance's delivered run
    for (double tol : {1e-4, 1e-7, 1e-10, 1e-12}) {
      std::string why;
      const MethodInfo& m = choose_method(b, c.scene.centres, tol, &why);
      adaptive::ToleranceResult r;
      try {
        r = adaptive::run_to_tolerance(m, b, c.scene.centres, Accuracy{tol, c.t_end}, kUnobserved,
                                       auto_verifies(c.scene.centres));  // as auto
      } catch (const Error& e) {
        // Below the probe's threshold the scene's round-off may be above tol: a refusal that says so is
        // the right answer when it is true.
        const std::string reason = e.what();
        ASSERT_LT(tol, bodypoint::kProbeBelowTol) << c.name << ": " << reason;
        ASSERT_NE(reason.find("round-off"), std::string::npos) << c.name << ": " << reason;
        ASSERT_TRUE(is_time_transformed(m)) << c.name;
        const double spread = rounding_spread(m, c, 0.25 * coarser_h);
        EXPECT_GT(spread, tol / kRefusalMargin) << c.name << ": " << reason;
        ++refused;
        std::printf("  %-22s tol %.0e  %-9s refused: %s (runs differing in rounding: %.2e)\n", c.name.c_str(), tol,
                    std::string(m.name).c_str(), reason.c_str(), spread);
        continue;
      }
      coarser_h = r.h;
      const double err = bodypoint::state_distance(r.result.final, ref);
      EXPECT_LE(err, tol) << c.name << " tol " << tol << " " << why;
      EXPECT_LE(r.err_estimate, tol) << c.name << " tol " << tol;
      if (err > kComparableError) {
        EXPECT_LE(r.err_estimate, kEstimateFactor * err) << c.name << " tol " << tol;
        EXPECT_GE(r.err_estimate, err / kEstimateFactor) << c.name << " tol " << tol;
      }
      // ks counts no force evaluations (its runs are alike: two of them).
      const double cost = r.result.force_evals > 0
                              ? static_cast<double>(r.total_force_evals) / static_cast<double>(r.result.force_evals)
                              : static_cast<double>(r.runs);
      const bool probed = tol < bodypoint::kProbeBelowTol && r.result.force_evals > 0;
      const double verify = auto_verifies(c.scene.centres) ? kVerifyRuns : 0.0;
      EXPECT_LE(cost, kMaxCostRatio + verify + (probed ? kProbeRounds * bodypoint::kProbeRuns : 0)) << c.name << " tol " << tol;
      worst_cost = std::max(worst_cost, cost);
      ++runs;
      within_decade += err >= 0.1 * tol ? 1 : 0;
      std::printf("  %-22s tol %.0e  %-9s h %-10.4g est %.2e err %.2e  (%d runs, %.2fx the delivered run)\n",
                  c.name.c_str(), tol, std::string(m.name).c_str(), r.h, r.err_estimate, err, r.runs, cost);
    }
  }
  std::printf("  delivered error within [tol/10, tol]: %d of %d; largest cost %.2fx the delivered run; %d refused"
              " for round-off\n", within_decade, runs, worst_cost, refused);
}

// Three centres of both signs, the body passing them at d = 10 with B = 0.8, at TOL 1e-7: the ladder's middle
// run sat where the error passes through zero (relative errors 3.5e-5 / 5.5e-8 / 1.8e-8 at ds = 0.31 / 0.15 /
// 0.095, an order of 9.3 over the three) and the delivered estimate was 8x below the error until a triple
// whose order is more than kOrderExcess above p was no longer trusted.
TEST(Tolerance, ATripleConvergingFarFasterThanOrderPIsNotTrusted) {
  Scene s = named_scene("three-centres").scene;
  SceneParams sp;
  sp.B = 0.8;
  sp.start.d = 10.0;
  s.bodies.front() = thesis_scene(sp).bodies.front();
  constexpr double kTol = 1e-7, kEnd = 80.0;
  const Body& b = s.bodies.front();
  // The ladder's own rule, unverified: ttl-kl6, auto's table at 1e-7 when this was measured.
  const MethodInfo& m = method_or_throw("ttl-kl6");
  const adaptive::ToleranceResult r = adaptive::run_to_tolerance(m, b, s.centres, Accuracy{kTol, kEnd}, kUnobserved, false);
  const double err = bodypoint::state_distance(r.result.final, reference_state(b, s.centres, kEnd, 1e-18L));
  EXPECT_LE(err, kTol);
  EXPECT_GE(r.err_estimate, err / kEstimateFactor) << m.name << " at ds " << r.h;
  EXPECT_LE(r.err_estimate, kEstimateFactor * err) << m.name << " at ds " << r.h;
}

// About several centres auto's answer is verified against a companion at a finer step (auto_verifies):
// unverified, three centres of both signs passed at d = 2 and 10 with B = 0.8 were delivered above TOL by
// every table auto may choose (ttl-kl6 at 1e-8, d = 2: 5.7e-8 with an estimate of 6.6e-10; ttl-pefrl at
// 1e-7, d = 10: 1.8e-7 with 5.3e-8; bench/estimate_grid.py --branches).
TEST(Tolerance, AutoAboutSeveralCentresDeliversTol) {
  constexpr double kEnd = 80.0;
  for (double d : {2.0, 10.0}) {
    SceneParams sp;
    sp.B = 0.8;
    sp.start.d = d;
    Scene s = thesis_scene(sp);
    s.centres.push_back({Vec3(40.0, 6.0, 0.0), 1.0});
    s.centres.push_back({Vec3(80.0, -8.0, 0.0), 1.5});
    ASSERT_TRUE(auto_verifies(s.centres));
    const Body& b = s.bodies.front();
    const State ref = reference_state(b, s.centres, kEnd, 1e-18L);
    for (double tol : {1e-7, 1e-8}) {
      Options o;
      o.track_invariants = false;
      const BodyResult r = integrate_body(b, s.centres, nullptr, Accuracy{tol, kEnd}, o);
      ASSERT_EQ(r.outcome, Outcome::ok) << r.reason;
      const double err = bodypoint::state_distance(r.run.final, ref);
      EXPECT_LE(err, tol) << r.method->name << " d " << d << " tol " << tol;
      EXPECT_GE(r.error.value, err / kEstimateFactor) << r.method->name << " d " << d << " tol " << tol;
    }
  }
}

// Where the pilot's coarse run already meets TOL, it is delivered with its error bounded by the finer runs
// (search/ladder.cpp, pilot_answer): on the thesis's scene at 1e-4 logh-verlet's ladder had gone on to a
// fourth run 4.0e-7 off, 250x below what was asked, for 1.6x the evaluations. The delivered error lies
// within kAskedDigits of TOL, and its bound is not below it.
constexpr double kAskedDigits = 100.0;
TEST(Tolerance, ThePilotsCoarseRunIsDeliveredWhereFinerRunsBoundIt) {
  const NamedScene ns = named_scene("thesis");
  const Body& b = ns.scene.bodies.front();
  constexpr double kTol = 1e-4;
  const adaptive::ToleranceResult r = adaptive::run_to_tolerance(method_or_throw("logh-verlet"), b, ns.scene.centres,
                                                                 Accuracy{kTol, ns.t_end}, kUnobserved, false);
  const double err = bodypoint::state_distance(r.result.final, reference_state(b, ns.scene.centres, ns.t_end));
  EXPECT_EQ(r.runs, 3) << "the pilot pair and the ladder's first refinement";
  EXPECT_LE(err, kTol);
  EXPECT_GE(err, kTol / kAskedDigits);
  EXPECT_GE(r.err_estimate, err) << "a bound by finer runs";
  EXPECT_LE(r.err_estimate, kTol);
}

// Where the pilot pair already shows its coarse run within TOL, the search's third run is one at twice the
// coarse step (half a coarse run) rather than a finer one (search/ladder.cpp, coarser_pilot_answer): a far pass
// (d = 60, B = 0.9) at 1e-9, logh-kl6, whose steps are the spin's at any ds, delivered its pilot's coarse run
// after a finer third run, the search 5.5 times that run (29,817 evaluations); the pilot pair and the coarser
// run make 3.5. The whole search is at most kCoarserPilotSearch delivered runs, the error within TOL and the
// estimate honest.
constexpr double kCoarserPilotSearch = 4.0;
TEST(Tolerance, APilotsCoarseRunWithinTolIsJudgedByACoarserRunNotAFinerOne) {
  SceneParams sp;
  sp.B = 0.9;
  sp.start.d = 60.0;
  const Scene s = thesis_scene(sp);
  const Body& b = s.bodies.front();
  constexpr double kTol = 1e-9, kEnd = 50.0;
  const adaptive::ToleranceResult r = adaptive::run_to_tolerance(method_or_throw("logh-kl6"), b, s.centres,
                                                                 Accuracy{kTol, kEnd}, kUnobserved, false);
  const double err = bodypoint::state_distance(r.result.final, reference_state(b, s.centres, kEnd));
  EXPECT_EQ(r.runs, 3) << "the pilot pair and the coarser run";
  EXPECT_LE(static_cast<double>(r.total_force_evals), kCoarserPilotSearch * static_cast<double>(r.result.force_evals));
  EXPECT_LE(err, kTol);
  EXPECT_LE(r.err_estimate, kTol);
  EXPECT_GE(r.err_estimate, err / kEstimateFactor);
}

// A verifying companion at h/2 lands on every point of the answer's grid and shares its rounding there
// (search/ladder.cpp, kVerifyRatio). On the rounded pass (common.hpp) logh-kl8 at 1e-10 was delivered
// 1.2e-10 off with 7.9e-11 estimated. Verified off the grid, the answer is within TOL or the search says TOL
// is out of reach.
TEST(Tolerance, AVerifiedAnswerOnARoundedPassIsWithinTolOrRefused) {
  const SceneParams sp = rounded_pass();
  const Scene s = thesis_scene(sp);
  const Body& b = s.bodies.front();
  const double t_end = rounded_pass_end(sp);
  const State ref = reference_state(b, s.centres, t_end);
  for (double tol : {1e-10, kRoundedPassTol}) {
    try {
      const adaptive::ToleranceResult r =
          adaptive::run_to_tolerance(method_or_throw("logh-kl8"), b, s.centres, Accuracy{tol, t_end}, kUnobserved);
      const double err = bodypoint::state_distance(r.result.final, ref);
      EXPECT_LE(err, tol) << "estimated " << r.err_estimate;
      EXPECT_GE(r.err_estimate, err / kEstimateFactor);
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("out of reach"), std::string::npos) << e.what();
      EXPECT_LT(tol, kRoundedPassTol) << e.what();
    }
  }
}

/// auto's answer to `tol` as `simulate --tol` runs it: its error against the long-double reference, its estimate.
struct AutoAnswer {
  double err, estimate;
  std::string method;
};
AutoAnswer auto_answer(const Scene& s, double tol, double t_end) {
  const Result r = integrate(s, "auto", Accuracy{tol, t_end});
  if (r.outcome != Outcome::ok || !r.bodies.front().accuracy) throw Error("auto did not answer: " + r.reason);
  const BodyResult& br = r.bodies.front();
  return {bodypoint::state_distance(br.run.final, reference_state(s.bodies.front(), s.centres, t_end, 1e-18L)),
          br.accuracy->err_estimate, std::string(br.method->name)};
}

// A ladder whose estimates stop falling where its runs differ by less than the far-field regime's differences
// (search/ladder.cpp, kStallBelow) may be comparing round-off: its answer is probed for it at any TOL. On this
// far pass (estimate_grid.py --branches, "lp far field") lp-kl6 at 1e-10 was delivered 2.5e-13 off with an
// estimate of 1.3e-14, its last triple showing the order by chance.
TEST(Tolerance, AStalledLadderProbesItsAnswersRoundingAtAnyTol) {
  SceneParams sp;
  sp.B = 0.9;
  sp.start.d = 300.0;
  sp.start.L = 1000.0;
  constexpr double kTol = 1e-10;
  const AutoAnswer a = auto_answer(thesis_scene(sp), kTol, 80.0);
  ASSERT_GT(a.err, kComparableError) << "the pass no longer tests the estimate";
  EXPECT_LE(a.err, kTol);
  EXPECT_GE(a.estimate, a.err / kEstimateFactor) << a.method;
}

// A new ladder's pair reading far below what the coarser runs predicted for it is judged by a third run
// (search/ladder.cpp, trusted()): on this scene of estimate_grid.py auto's logh-pefrl at 1e-7 was delivered
// 1.45e-8 off with its pair's 3.8e-9, where the model had predicted 3e-8.
TEST(Tolerance, APairFarBelowItsPredictionIsJudgedByAThirdRun) {
  SceneParams sp;
  sp.B = 0.8;
  sp.start.d = 8.0;
  sp.start.Kz = 5.0;
  sp.start.Kx = -1.0;
  constexpr double kTol = 1e-7;
  const AutoAnswer a = auto_answer(thesis_scene(sp), kTol, 80.0);
  ASSERT_GT(a.err, kComparableError);
  EXPECT_LE(a.err, kTol);
  EXPECT_GE(a.estimate, a.err / kEstimateFactor) << a.method;
  EXPECT_LE(a.estimate, a.err * kEstimateFactor) << a.method;
}

TEST(Tolerance, ADeliveredRunTooLongToKeepIsMadeAgainForItsSamples) {
  // A run that may be delivered keeps its samples for the caller's sink up to 2^20 of them (adaptive/
  // search/runs.cpp); a scattering run under events at tol 1e-10 kept every step of its finest rungs and was
  // killed at 24 GB. Beyond that it drops them and makes the delivered run again with the sink.
  constexpr long kKeptAtMost = 1L << 20;
  const NamedScene ns = named_scene("thesis");
  const Body& b = ns.scene.bodies.front();
  const MethodInfo& m = method_or_throw("lp-verlet");
  long count = 0, last_step = -1;
  bool in_order = true;
  State last;
  SampleSink sink = [&](const Sample& x) {
    in_order = in_order && x.step == last_step + 1;
    last_step = x.step;
    last = x.s;
    ++count;
  };
  RunOptions o;
  o.track_invariants = false;
  o.sink = &sink;
  const adaptive::ToleranceResult r = adaptive::run_to_tolerance(m, b, ns.scene.centres, Accuracy{1e-10, 40.0}, o, false);
  ASSERT_GT(r.steps, kKeptAtMost) << "the delivered run must be longer than what is kept";
  EXPECT_TRUE(in_order);
  EXPECT_EQ(count, r.steps + 1) << "every step and the start";
  EXPECT_EQ(last.R, r.result.final.R) << "the run made again is the delivered run, bit for bit";
  EXPECT_EQ(last.v, r.result.final.v);
}

TEST(Tolerance, EveryFamilyAcceptsTol) {
  const NamedScene ns = named_scene("close");
  const Body& b = ns.scene.bodies.front();
  const State ref = reference_state(b, ns.scene.centres, ns.t_end, 1e-18L);
  constexpr double tol = 1e-8;
  for (const char* name : {"lp-rkn6", "lp-kl8", "logh-y4", "logh-kl6", "ttl-bm4", "ttl-mcl8"}) {
    const adaptive::ToleranceResult r =
        adaptive::run_to_tolerance(method_or_throw(name), b, ns.scene.centres, Accuracy{tol, ns.t_end}, kUnobserved);
    EXPECT_LE(bodypoint::state_distance(r.result.final, ref), tol) << name;
  }
}

TEST(Tolerance, AutoChoosesByTheScene) {
  auto chosen = [](const Scene& s, double tol) -> const MethodInfo& {
    return choose_method(s.bodies.front(), s.centres, tol, nullptr);
  };
  auto family = [&](const Scene& s, double tol) {
    const std::string name = chosen(s, tol).name;
    return name.substr(0, name.find('-'));
  };
  SceneParams material;
  material.B = 0.0;
  EXPECT_EQ(std::string(chosen(thesis_scene(material), 1e-8).name), "ks");
  SceneParams attracting;
  attracting.A = 2.0;
  SceneParams far;  // a spinning body passing a weak centre at a distance of 1e4
  far.A = -1e-3;
  far.start.d = 1e4;
  const std::vector<std::pair<Scene, std::string>> by_family = {
      {thesis_scene(attracting), "ttl"}, {named_scene("close").scene, "logh"}, {thesis_scene(far), "lp"}};
  for (const auto& [scene, expected] : by_family) {
    // The table is the one whose search was measured cheapest (lib/api/auto.cpp, kMeasuredCost): at 1e-4,
    // where every table's step is bounded by the spin, Verlet, the fewest stages; at 1e-6 not Verlet (its
    // searches measured 3.4x the cheapest); no looser tol takes a higher order than a tighter one.
    EXPECT_EQ(std::string(chosen(scene, 1e-4).table), "verlet") << expected;
    EXPECT_GE(chosen(scene, 1e-6).order, 4) << expected;
    int order = 0;
    for (double tol : {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13}) {
      EXPECT_EQ(family(scene, tol), expected) << tol;
      EXPECT_GE(chosen(scene, tol).order, order) << expected << " " << tol;
      order = chosen(scene, tol).order;
    }
    EXPECT_GE(order, 8) << expected << ": the tightest tol takes an order-8 table";
  }
  // A spinning body drifts along K1, not along v (which precesses about K1): from far starts aimed at
  // the centre (d = 0.5) the encounter is close, whatever L. Predicted along v, L >= 500 read as
  // "stays far" and chose lp-kl6, 20x the force evaluations of logh-kl6 at L = 1000.
  for (double L : {200.0, 1e3, 1e4}) {
    SceneParams aimed;
    aimed.start.L = L;
    aimed.start.d = 0.5;
    EXPECT_EQ(family(thesis_scene(aimed), 1e-9), "logh") << L;
  }
}

// far-ip's estimate is the largest difference of its run to a run at h/1.25 and a run from a start moved
// by 4 ulp (search/exact_pair.cpp): draws of the scene's amplified rounding, which is most of its error.
// It may stand above the delivered run's error by more than kEstimateFactor (its own rounding is about one
// ulp of the start; a close pass: 5.96e-12 for 1.77e-12; bench/estimate_grid.py --method far-ip: a median of
// 2.4x over its 366 measurable runs, above 10x only for errors of at most 1.5e-12), by at most this much on
// these scenes, and never below it by more than kEstimateFactor.
constexpr double kPairOverstates = 10.0;

// far-ip (spectral in its step, no order p) under tol: runs at h and h/1.25 and from starts moved by a
// rounding. Delivered within tol on a far pass (figure 11's), between centres of both
// signs, on two-centres, swinging round an attracting centre and on a close pass; the estimate at most
// kPairOverstates above the error and never more than kEstimateFactor below it, where the error is
// measurable; a refusal only below kProbeBelowTol (1e-12, 1e-13), quoting a floor above tol/kRefusalMargin.
TEST(Tolerance, FarIpDeliversTolWithTheEstimateOfItsPair) {
  std::vector<Case> all;
  for (Case& c : cases())
    if (c.name == "close" || c.name == "two-centres" || c.name == "both-signs" || c.name == "attracting")
      all.push_back(std::move(c));
  {
    SceneParams sp;  // the far pass of figure 11 (docs/physics.md, "The far field in the interaction picture")
    sp.start.d = 50.0;
    sp.start.Kz = 0.1;
    all.push_back({"far-pass", from_params(sp), 80.0});
  }
  const MethodInfo& m = method_or_throw("far-ip");
  int delivered = 0, refused = 0;
  for (const Case& c : all) {
    const Body& b = c.scene.bodies.front();
    const State ref = reference_state(b, c.scene.centres, c.t_end, 1e-18L);
    // The close pass takes far-ip's finest steps (525,181 force evaluations at its first): one TOL there.
    const std::vector<double> tols = c.name == "close" ? std::vector<double>{1e-7} : std::vector<double>{1e-7, 1e-10, 1e-12, 1e-13};
    for (double tol : tols) {
      try {
        const adaptive::ToleranceResult r =
            adaptive::run_to_tolerance(m, b, c.scene.centres, Accuracy{tol, c.t_end}, kUnobserved);
        const double err = bodypoint::state_distance(r.result.final, ref);
        EXPECT_LE(err, tol) << c.name << " tol " << tol;
        EXPECT_LE(r.err_estimate, tol) << c.name << " tol " << tol;
        if (err > kComparableError) {
          EXPECT_LE(r.err_estimate, kPairOverstates * err) << c.name << " tol " << tol;
          EXPECT_GE(r.err_estimate, err / kEstimateFactor) << c.name << " tol " << tol;
        }
        ++delivered;
        std::printf("  %-22s tol %.0e  far-ip h %-10.4g est %.2e err %.2e  (%d runs, %ld force evaluations)\n",
                    c.name.c_str(), tol, r.h, r.err_estimate, err, r.runs, r.total_force_evals);
      } catch (const Error& e) {
        const std::string reason = e.what();
        EXPECT_LT(tol, bodypoint::kProbeBelowTol) << c.name << ": " << reason;
        const std::string floor_said = "was at least ";
        const auto at = reason.find(floor_said);
        ASSERT_NE(at, std::string::npos) << c.name << ": " << reason;
        EXPECT_GT(std::stod(reason.substr(at + floor_said.size())), tol / kRefusalMargin) << reason;
        ++refused;
        std::printf("  %-22s tol %.0e  far-ip refused: %s\n", c.name.c_str(), tol, reason.c_str());
      }
    }
  }
  EXPECT_GT(delivered, refused);
  EXPECT_GT(refused, 0);  // both-signs at 1e-13: its run errs 1.06e-13
  std::printf("  far-ip: %d delivered, %d refused\n", delivered, refused);
}

TEST(Tolerance, UnreachableOrInvalidTolIsRefused) {
  const NamedScene ns = named_scene("close");
  const Body& b = ns.scene.bodies.front();
  for (double tol : {0.0, -1e-6, std::nan(""), 1e-20, 2.0})
    EXPECT_THROW(bodypoint::check_tolerance(tol), Error) << tol;
  // An adaptive peer controls its own step: the search refuses it.
  EXPECT_THROW(adaptive::run_to_tolerance(method_or_throw("odeint-rkf78"), b, ns.scene.centres, Accuracy{1e-8, 80.0}, kUnobserved), Error);
}

// A strongly coupled spinning body (B = 0.9) aimed at the centre (b = 1): runs of logh-kl8 at finer
// steps stop agreeing better than a few 1e-12 (the encounter amplifies round-off), so tol 1e-12 is
// refused, and the refusal quotes that floor, not an early pair that happened to agree (it quoted
// 9.9e-15 before). Ten times looser is delivered.
TEST(Tolerance, ARefusalQuotesTheFloorItMet) {
  SceneParams sp;
  sp.B = 0.9;
  sp.start.Kx = 2.0;
  sp.start.Kz = 5.0;
  sp.start.d = d_for_impact_parameter(sp, 1.0);
  const Scene scene = thesis_scene(sp);
  const Body& b = scene.bodies.front();
  const auto k = kepler_particle(b.p, b.s0, scene.centres.front().c);
  ASSERT_TRUE(k.has_value());
  const double t_end = 2.0 * sp.start.L / (k->P.norm() / k->mu);
  const MethodInfo& m = method_or_throw("logh-kl8");
  constexpr double kAsked = 1e-12, kLooser = 1e-11;
  try {
    adaptive::run_to_tolerance(m, b, scene.centres, Accuracy{kAsked, t_end}, kUnobserved);
    ADD_FAILURE() << "tol " << kAsked << " was delivered; this scene's floor moved (choose another)";
  } catch (const Error& e) {
    const std::string why = e.what();
    const std::string key = "differ by ";
    const auto at = why.find(key);
    ASSERT_NE(at, std::string::npos) << why;
    EXPECT_NE(why.find("out of reach"), std::string::npos) << why;
    EXPECT_GT(std::stod(why.substr(at + key.size())), kAsked) << why;
  }
  const State ref = reference_state(b, scene.centres, t_end, 1e-18L);
  const adaptive::ToleranceResult r = adaptive::run_to_tolerance(m, b, scene.centres, Accuracy{kLooser, t_end}, kUnobserved);
  EXPECT_LE(bodypoint::state_distance(r.result.final, ref), kLooser);
  // Ten times tighter than the floor, a pair at the answer's step and twice it agreed with C h^p by
  // chance and was delivered 38x off (estimate 1.9e-14, error 3.8e-12) until runs differing only in
  // rounding were compared: now refused, or delivered within tol.
  constexpr double kBelowFloor = 1e-13;
  try {
    const adaptive::ToleranceResult below = adaptive::run_to_tolerance(m, b, scene.centres, Accuracy{kBelowFloor, t_end}, kUnobserved);
    EXPECT_LE(bodypoint::state_distance(below.result.final, ref), kBelowFloor) << "delivered below the floor";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("out of reach"), std::string::npos) << e.what();
  }
}

TEST(Tolerance, CommandLine) {
  const test::CliResult ok = test::run_cli("simulate --tol 1e-8 --Kz 0.1 --d 0.05 --t-end 80 --json");
  ASSERT_EQ(ok.code, 0) << ok.err;
  // The command line delivers the library's choice for the same scene (named scene close).
  const NamedScene close = named_scene("close");
  const std::string method = choose_method(close.scene.bodies.front(), close.scene.centres, 1e-8, nullptr).name;
  EXPECT_NE(ok.out.find("\"method\": \"" + method + "\""), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("\"err_estimate\": "), std::string::npos);
  EXPECT_NE(ok.out.find("\"chosen\": "), std::string::npos);
  for (const char* bad : {"--tol 0", "--tol nan", "--tol 1e-20", "--tol -1", "--method auto",
                          "--tol 1e-8 --h 0.01", "--tol 1e-8 --omega-c 1"}) {
    const test::CliResult r = test::run_cli(std::string("simulate --t-end 10 ") + bad);
    EXPECT_EQ(r.code, 2) << bad << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << bad << ": one line, got " << r.err;
  }
}

}  // namespace
}  // namespace bodypoint
