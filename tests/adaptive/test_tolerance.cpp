// --tol and --method auto (adaptive/tolerance.hpp): accuracy only, no timing.
//
// Every run is checked against Boost.Odeint rkf78 in long double at tolerance 1e-18 on scenes the
// step search was not tuned on as well as on the named ones: several centres of both signs, near
// head-on encounters, B = 0 and B != 0, an end time long after the encounter.
#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/run.hpp"
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

// The search delivers a run whose estimate is at most half of TOL and whose estimate tracks its true
// error; the requirement is that the estimate is within this factor of the true error.
constexpr double kEstimateFactor = 10.0;
// An underestimate beyond kEstimateFactor would be a broken promise and is never allowed. An
// overestimate beyond it happens where the delivered step sits in a dip of the error curve (both-signs,
// ttl-kl8 at ds = 0.1016: error 3.0e-10 while its neighbours at 1.1 and 1.21 times that step follow
// C h^8 from 5e-9, so every estimate from them says 4e-9); at most this fraction of the grid may.
constexpr double kMaxOverestimatedFraction = 0.1;
// Below this the "true" error is the reference's own error and the round-off of the run
// (reference rkf78 long double tol 1e-18: 1e-15..1e-14 relative; runs: 1e-15..1e-13), so the
// estimate is compared with the error only above it.
constexpr double kComparableError = 1e-13;

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

// The grid stops at 1e-10. At 1e-12 auto also delivered on seven of these eight scenes, but on
// close-long (t = 400, ~1e5 steps of logh-kl8) it delivered 1.8e-12 with an estimate of 2.2e-13: the
// round-off of that many steps is not systematic in h, so Richardson estimates do not see it (README,
// "Limits").
TEST(Tolerance, AutoDeliversTolWithAnHonestEstimate) {
  int runs = 0, overestimated = 0;
  for (const Case& c : cases()) {
    const Body& b = c.scene.bodies.front();
    const State ref = reference_state(b, c.scene.centres, c.t_end, 1e-18L);
    for (double tol : {1e-4, 1e-7, 1e-10}) {
      std::string why;
      const MethodInfo& m = choose_method(b, c.scene.centres, tol, &why);
      const adaptive::ToleranceResult r = adaptive::run_to_tolerance(m, b, c.scene.centres, tol, c.t_end);
      const double err = adaptive::state_distance(r.result.final, ref);
      EXPECT_LE(err, tol) << c.name << " tol " << tol << " " << why;
      EXPECT_LE(r.err_estimate, 0.5 * tol) << c.name << " tol " << tol;
      // The estimate is an estimate of err: within kEstimateFactor of it, where err is measurable.
      ++runs;
      if (r.err_estimate > kEstimateFactor * std::max(err, kComparableError)) ++overestimated;
      if (err > kComparableError) {
        EXPECT_GE(r.err_estimate, err / kEstimateFactor) << c.name << " tol " << tol;
      }
      std::printf("  %-22s tol %.0e  %-9s h %-10.4g est %.2e err %.2e  (%d runs)\n", c.name.c_str(), tol,
                  std::string(m.name).c_str(), r.h, r.err_estimate, err, r.runs);
    }
  }
  EXPECT_LE(overestimated, kMaxOverestimatedFraction * runs) << overestimated << " of " << runs;
  std::printf("  estimates more than %.0fx above the error: %d of %d\n", kEstimateFactor, overestimated, runs);
}

TEST(Tolerance, EveryFamilyAcceptsTol) {
  const NamedScene ns = named_scene("close");
  const Body& b = ns.scene.bodies.front();
  const State ref = reference_state(b, ns.scene.centres, ns.t_end, 1e-18L);
  constexpr double tol = 1e-8;
  for (const char* name : {"lp-rkn6", "lp-kl8", "logh-y4", "logh-kl6", "ttl-bm4", "ttl-mcl8"}) {
    const adaptive::ToleranceResult r =
        adaptive::run_to_tolerance(method_or_throw(name), b, ns.scene.centres, tol, ns.t_end);
    EXPECT_LE(adaptive::state_distance(r.result.final, ref), tol) << name;
  }
  // The delivered run repeats exactly from its spec (with invariants tracked).
  const MethodInfo& m = method_or_throw("logh-bm4");
  const adaptive::ToleranceResult r = adaptive::run_to_tolerance(m, b, ns.scene.centres, tol, ns.t_end);
  RunSpec spec;
  spec.track_invariants = true;
  const RunResult again = run(m, b, ns.scene.centres, adaptive::delivered_spec(m, r, ns.t_end, spec));
  EXPECT_LE(adaptive::state_distance(again.final, r.result.final), kComparableError);
}

TEST(Tolerance, AutoChoosesByTheScene) {
  auto chosen = [](const Scene& s, double tol) {
    return std::string(choose_method(s.bodies.front(), s.centres, tol, nullptr).name);
  };
  SceneParams material;
  material.B = 0.0;
  EXPECT_EQ(chosen(thesis_scene(material), 1e-8), "ks");
  SceneParams attracting;
  attracting.A = 2.0;
  EXPECT_EQ(chosen(thesis_scene(attracting), 1e-4), "ttl-y4");
  EXPECT_EQ(chosen(thesis_scene(attracting), 1e-8), "ttl-kl6");
  EXPECT_EQ(chosen(thesis_scene(attracting), 1e-11), "ttl-kl8");
  EXPECT_EQ(chosen(named_scene("close").scene, 1e-4), "logh-y4");
  EXPECT_EQ(chosen(named_scene("close").scene, 1e-10), "logh-kl6");
  EXPECT_EQ(chosen(named_scene("close").scene, 1e-11), "logh-kl8");
  SceneParams far;  // a spinning body passing a weak centre at a distance of 1e4
  far.A = -1e-3;
  far.start.d = 1e4;
  EXPECT_EQ(chosen(thesis_scene(far), 1e-11), "lp-kl8");
}

TEST(Tolerance, UnreachableOrInvalidTolIsRefused) {
  const NamedScene ns = named_scene("close");
  const Body& b = ns.scene.bodies.front();
  for (double tol : {0.0, -1e-6, std::nan(""), 1e-20, 2.0})
    EXPECT_THROW(adaptive::check_tolerance(tol), Error) << tol;
  // An adaptive peer controls its own step: the search refuses it.
  EXPECT_THROW(adaptive::run_to_tolerance(method_or_throw("odeint-rkf78"), b, ns.scene.centres, 1e-8, 80.0), Error);
}

TEST(Tolerance, CommandLine) {
  const test::CliResult ok = test::run_cli("simulate --tol 1e-8 --Kz 0.1 --d 0.05 --t-end 80 --json");
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.out.find("\"method\": \"logh-kl6\""), std::string::npos) << ok.out;
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
