// Model, initial conditions, equations of motion and input validation.
#include "bodypoint/field.hpp"
#include "bodypoint/detail/monitor.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/detail/equations.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/scene_file.hpp"
#include "bodypoint/sweep.hpp"
#include "common.hpp"
#include "sweep_tasks.hpp"
#include "bodypoint/detail/run_parts.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <type_traits>

namespace bodypoint {
namespace {

// Conversions and the thesis's start involve a handful of roundings of O(10) numbers.
constexpr double kConversionTol = 1e-13;
// dK1/dt and dK2Q/dt are sums of terms of size |F| ~ 1e-2..1 and B^2|w x v|/D ~ 10^2 for the random
// states below; their exact cancellation leaves only rounding of that size.
constexpr double kIdentityTol = 1e-11;
// With the printed signs dK1/dt misses F by O(B^2 |w x v|/D) ~ 1e2, far above rounding.
constexpr double kPrintedSignGap = 1e3;

TEST(InitialConditions, ReproduceThesisEquations) {
  SceneParams sp;  // table 3.1
  const Scene s = thesis_scene(sp);
  const Body& b = s.bodies.front();
  const Momenta q = to_momenta(b.p, b.s0);
  EXPECT_NEAR((q.K1 - Vec3(5, 0, 0)).norm(), 0.0, kConversionTol);
  EXPECT_NEAR((q.K2 - Vec3(2, 0, -5)).norm(), 0.0, kConversionTol);
  EXPECT_NEAR((q.R - Vec3(-200, 9, 0)).norm(), 0.0, kConversionTol);  // table 3.1: R(0) = 9 j - 200 i
  const Vec3 K2Q = total_angular_momentum(b.p, b.s0, Vec3::Zero());
  EXPECT_NEAR(K2Q.z(), -sp.start.d * sp.start.K1, kConversionTol);
  // Eq. 1.14-1.15 written out by the thesis.
  const double m = 1, B = 0.7, J = 1, K1 = 5, Kx = 2, Kz = 5, den = B * B - m * J;
  EXPECT_NEAR((b.s0.v - Vec3((B * Kx - J * K1) / den, 0, -B * Kz / den)).norm(), 0.0, kConversionTol);
  EXPECT_NEAR((b.s0.w - Vec3((B * K1 - m * Kx) / den, 0, m * Kz / den)).norm(), 0.0, kConversionTol);
}

TEST(InitialConditions, HelixOfTheThesisStartCirclesItsGuidingCentre) {
  SceneParams sp;  // table 3.1: G = (-L, d, 0), the body at R = (-L, d - Kz/K1, 0)
  const Scene s = thesis_scene(sp);
  const Body& b = s.bodies.front();
  const Helix h = helix_of(b.p, to_momenta(b.p, b.s0));
  EXPECT_NEAR((h.centre - Vec3(-sp.start.L, sp.start.d, 0)).norm(), 0.0, kConversionTol);
  EXPECT_NEAR(h.radius, sp.start.Kz / sp.start.K1, kConversionTol);
  // G moves along K1 at v's mean over a turn: at this start v has no part along K1 that turns.
  EXPECT_NEAR((h.velocity - Vec3(b.s0.v.x(), 0, 0)).norm(), 0.0, kConversionTol);
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_NEAR(path_distance(h, Vec3::Zero(), inf), sp.start.d, kConversionTol);   // passes the centre at d
  EXPECT_NEAR(path_distance(h, Vec3::Zero(), 0.0), h.centre.norm(), kConversionTol);  // no time: where it is
  const Vec3 behind(-2 * sp.start.L, 0, 0);
  EXPECT_NEAR(path_distance(h, behind, inf), (h.centre - behind).norm(), kConversionTol);  // moving away
  const double t = 3.0;
  EXPECT_NEAR(path_distance(h, Vec3::Zero(), t), (h.centre + t * h.velocity).norm(), kConversionTol);
  // A material point has no helix: G is R and moves at v.
  const BodyPoint point{1.0, 0.0, 1.0};
  const Helix m = helix_of(point, to_momenta(point, b.s0));
  EXPECT_EQ(m.radius, 0.0);
  EXPECT_NEAR((m.centre - b.s0.R).norm(), 0.0, kConversionTol);
  EXPECT_NEAR((m.velocity - b.s0.v).norm(), 0.0, kConversionTol);
}

TEST(InitialConditions, MomentaRoundTrip) {
  const BodyPoint p{1.3, -0.4, 0.8};
  const State s{Vec3(1, 2, 3), Vec3(-0.5, 0.25, 2), Vec3(3, -1, 0.5)};
  const State back = to_state(p, to_momenta(p, s));
  EXPECT_NEAR((back.v - s.v).norm(), 0.0, kConversionTol);
  EXPECT_NEAR((back.w - s.w).norm(), 0.0, kConversionTol);
}

/// The thesis's printed eq. 1.10 (both signs flipped), to show the identity test catches it.
OdeState<double> thesis_printed_rhs(const BodyPoint& p, double A, const OdeState<double>& x) {
  const State s = from_ode(x);
  const double r3 = std::pow(s.R.norm(), 3);
  const Vec3 wxv = s.w.cross(s.v);
  const Vec3 dv = (-A * p.J / r3 * s.R - p.B * p.B * wxv) / p.D();
  const Vec3 dw = (-A * p.B / r3 * s.R - p.m * p.B * wxv) / p.D();  // eq. 1.10 as printed
  return to_ode(State{s.v, dv, dw});
}

TEST(EquationsOfMotion, LinearMomentumObeysForceAndAngularMomentumIsConstant) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-10, 10);
  const BodyPoint p{1.0, 0.7, 1.0};
  const double A = -2.0;
  EquationsOfMotion<OriginCentre, true> eom{p, OriginCentre{A}};
  for (int trial = 0; trial < 100; ++trial) {
    const State s{Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng))};
    OdeState<double> dx;
    eom(to_ode(s), dx, 0.0);
    const State d = from_ode(dx);  // (dR, dv, dw)
    const Vec3 F = OriginCentre{A}.force(s.R);
    const Vec3 dK1 = p.m * d.v + p.B * d.w;
    EXPECT_LT((dK1 - F).norm(), kIdentityTol) << "dK1/dt = F violated";
    const Vec3 K1 = p.m * s.v + p.B * s.w;
    const Vec3 dK2Q = d.R.cross(K1) + s.R.cross(dK1) + p.B * d.v + p.J * d.w;
    EXPECT_LT(dK2Q.norm(), kIdentityTol) << "d(R x K1 + K2)/dt = 0 violated";

    const State dp = from_ode(thesis_printed_rhs(p, A, to_ode(s)));
    const Vec3 dK1_printed = p.m * dp.v + p.B * dp.w;
    EXPECT_GT((dK1_printed - F).norm(), kPrintedSignGap * kIdentityTol) << "the identity must reject eq. 1.10 as printed";
  }
}

TEST(Invariants, EnergyUsesFullCouplingTerm) {
  // Erratum 2: the coupling term is B v.w, not B/2 v.w.
  const BodyPoint p{2.0, 0.5, 3.0};
  const State s{Vec3(1, 0, 0), Vec3(1, 2, 3), Vec3(-1, 0.5, 2)};
  const double T = 0.5 * 2.0 * 14.0 + 0.5 * (-1 + 1 + 6) + 0.5 * 3.0 * 5.25;
  EXPECT_DOUBLE_EQ(kinetic_energy(p, s), T);
  EXPECT_DOUBLE_EQ(energy(p, OriginCentre{-2.0}, s), T + 2.0);
}

// ---- validation: every rule has a test -------------------------------------------------------

Scene scene_with(const BodyPoint& p, const Vec3& R = Vec3(-10, 1, 0)) {
  Scene s;
  s.centres.push_back({Vec3::Zero(), -2.0});
  s.bodies.push_back({p, State{R, Vec3(1, 0, 0), Vec3::Zero()}, "b"});
  return s;
}

void expect_error(const std::function<void()>& f, const std::string& fragment) {
  try {
    f();
    ADD_FAILURE() << "no error, expected one mentioning '" << fragment << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

// The thesis code's law, written out: F = -A R/|R|^1.5 (BodyPointEquationWithoutTensors.java divides by
// Math.pow(|R|, 3.0/2.0)). Two evaluations of the same formula in a different order: a few roundings.
constexpr double kLawTol = 1e-15;

TEST(ForceLaw, ThesisCodeDividesByRToTheOneAndAHalf) {
  const Vec3 R(3, -4, 12);  // |R| = 13
  const double A = -2.0;
  CentreList code{{Centre{Vec3::Zero(), A, ForceLaw::thesis_code_force}}};
  CentreList coulomb{{Centre{Vec3::Zero(), A, ForceLaw::coulomb}}};
  EXPECT_NEAR((code.force(R) - (-A / std::pow(13.0, 1.5)) * R).norm(), 0.0, kLawTol);
  EXPECT_NEAR((coulomb.force(R) - (-A / (13.0 * 13.0 * 13.0)) * R).norm(), 0.0, kLawTol);
  // The code's energy diagnostic keeps -A/|R| (Energy.java, getPotentialEnergy).
  EXPECT_DOUBLE_EQ(code.potential(R), -A / 13.0);
  // A non-Coulomb centre never takes the OriginCentre fast path.
  const bool list = visit_field(code.centres, [](const auto& f) {
    return std::is_same_v<std::decay_t<decltype(f)>, CentreList>;
  });
  EXPECT_TRUE(list);
}

TEST(ForceLaw, SlipMovesOnlyThirdKickSchemesAndOnlyUnderTheCodeLaw) {
  SceneParams sp;
  sp.law = ForceLaw::thesis_code_force;
  const Scene force_only = thesis_scene(sp);
  sp.law = ForceLaw::thesis_code;
  const Scene code = thesis_scene(sp);
  FlatRun rs;
  rs.h = 1e-3;
  rs.steps = 5000;
  auto final_R = [&](const char* m, const Scene& sc) { return run(method_or_throw(m), sc.bodies.front(), sc.centres, rs).final.R; };
  // Schemes with fewer than three kicks and every non-thesis method are untouched, bit for bit.
  for (const char* m : {"thesis-euler", "thesis-verlet", "lp-y4", "rk4"})
    EXPECT_EQ(final_R(m, force_only), final_R(m, code)) << m;
  // Ruth 3, Forest-Ruth 4 and Yoshida 6 take the slip: their results move.
  for (const char* m : {"thesis-ruth3", "thesis-fr4", "thesis-y6"})
    EXPECT_NE(final_R(m, force_only), final_R(m, code)) << m;
}

// The code's loop (SymplecticEulerForSystem.java and the others: i = 1; do { ...; i++; } while (i < n)):
// n - 1 steps of exactly h, n = (int)(T / h) when a time is given (IntegrateStepTest).
TEST(ForceLaw, TheCodesLoopTakesOneStepFewerThanAsked) {
  EXPECT_EQ(thesis_code_steps(1e-4, 250000, 0.0).steps, 249999);
  EXPECT_EQ(thesis_code_steps(1e-4, 0, 25.0).steps, 249999);
  EXPECT_EQ(thesis_code_steps(0.3, 0, 1.0).steps, 2);  // (int)(1/0.3) = 3, truncated, not rounded up
  EXPECT_EQ(thesis_code_steps(0.3, 0, 1.0).h, 0.3);    // h is never adjusted to land on T
  EXPECT_THROW((void)thesis_code_steps(1e-3, 1, 0.0), Error) << "n = 1 takes no step";
  EXPECT_THROW((void)thesis_code_steps(0.0, 10, 0.0), Error);
  // The sweeps' run specification counts so under the code's law only.
  EXPECT_EQ(sweep_steps(1e-4, 250000, 0.0, ForceLaw::thesis_code).steps, 249999);
  EXPECT_EQ(sweep_steps(1e-4, 250000, 0.0, ForceLaw::thesis_code_force).steps, 250000);
  EXPECT_EQ(sweep_steps(1e-4, 250000, 0.0).steps, 250000);
}

TEST(ForceLaw, TimeTransformedMethodsAndTolRefuseTheCodeLaw) {
  SceneParams sp;
  sp.law = ForceLaw::thesis_code;
  const Scene sc = thesis_scene(sp);
  FlatRun rs;
  rs.h = 1e-2;
  rs.steps = 10;
  for (const char* m : {"logh-y4", "ttl-y4"})
    EXPECT_THROW((void)run(method_or_throw(m), sc.bodies.front(), sc.centres, rs), Error) << m;
}

TEST(Validation, RejectsNonPositiveMassInertiaAndD) {
  expect_error([] { validate(scene_with({0.0, 0.0, 1.0})); }, "mass m must be > 0");
  expect_error([] { validate(scene_with({-1.0, 0.0, 1.0})); }, "mass m must be > 0");
  expect_error([] { validate(scene_with({1.0, 0.0, 0.0})); }, "inertia J must be > 0");
  expect_error([] { validate(scene_with({1.0, 1.0, 1.0})); }, "D = m J - B^2 must be > 0");
  expect_error([] { validate(scene_with({1.0, 2.0, 1.0})); }, "D = m J - B^2 must be > 0");
  expect_error([] { validate(scene_with({1e308, 0.0, 1e308})); }, "D = m J - B^2 overflows");
}

TEST(Validation, RejectsNonFiniteNumbers) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  expect_error([&] { validate(scene_with({nan, 0.0, 1.0})); }, "finite");
  expect_error([&] { validate(scene_with({1.0, inf, 1.0})); }, "finite");
  expect_error([&] { validate(scene_with({1.0, 0.0, 1.0}, Vec3(nan, 0, 0))); }, "finite");
  Scene s = scene_with({1.0, 0.0, 1.0});
  s.centres[0].A = inf;
  expect_error([&] { validate(s); }, "finite");
  SceneParams sp;
  sp.start.d = nan;
  expect_error([&] { thesis_scene(sp); }, "finite");
}

TEST(Validation, RejectsBodyOnCentreAndEmptyScenes) {
  expect_error([] { validate(scene_with({1.0, 0.0, 1.0}, Vec3::Zero())); }, "starts on centre");
  Scene s = scene_with({1.0, 0.0, 1.0});
  s.centres.clear();
  expect_error([&] { validate(s); }, "no Coulomb centre");
}

/// validate's message of `s`, or "" where it accepts it.
std::string thrown_by_validate(const Scene& s) {
  try {
    validate(s);
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

TEST(Validation, WhyInvalidIsValidatesMessageAsAValue) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Scene> scenes = {scene_with({1.0, 0.0, 1.0}), scene_with({0.0, 0.0, 1.0}), scene_with({1.0, 2.0, 1.0}),
                               scene_with({1.0, 0.0, 1.0}, Vec3(nan, 0, 0)), scene_with({1.0, 0.0, 1.0}, Vec3::Zero()),
                               scene_with({1.0, 0.0, 1.0}, Vec3(1e200, 0, 0))};
  scenes.push_back(scene_with({1.0, 0.0, 1.0}));
  scenes.back().bodies.clear();
  int refused = 0;
  for (const Scene& s : scenes) {
    EXPECT_EQ(why_invalid(s), thrown_by_validate(s));
    refused += why_invalid(s).empty() ? 0 : 1;
  }
  EXPECT_EQ(refused, static_cast<int>(scenes.size()) - 1);  // all but the first
  SceneParams sp;
  EXPECT_EQ(why_invalid(sp), "");
  EXPECT_EQ(why_invalid(thesis_scene(sp)), "");
  for (double& (*field)(SceneParams&) : {+[](SceneParams& q) -> double& { return q.start.d; },
                                         +[](SceneParams& q) -> double& { return q.start.K1; },
                                         +[](SceneParams& q) -> double& { return q.J; }}) {
    SceneParams bad;
    field(bad) = nan;
    const std::string why = why_invalid(bad);
    EXPECT_NE(why.find("must be a finite number"), std::string::npos) << why;
    expect_error([&] { thesis_scene(bad); }, why);
  }
  sp.start.K1 = 0.0;
  EXPECT_EQ(why_invalid(sp), "K1 must be non-zero (R(0) contains Kz/K1)");
}

TEST(Validation, RejectsBadStepsAndUnknownMethod) {
  const Scene s = test::table31();
  FlatRun spec;
  spec.steps = 10;
  spec.h = 0.0;
  expect_error([&] { run(method_or_throw("rk4"), s.bodies[0], s.centres, spec); }, "the step h");
  spec.h = -1e-3;
  expect_error([&] { run(method_or_throw("rk4"), s.bodies[0], s.centres, spec); }, "the step h");
  spec.h = std::numeric_limits<double>::quiet_NaN();
  expect_error([&] { run(method_or_throw("rk4"), s.bodies[0], s.centres, spec); }, "the step h");
  spec.h = 1e-3;
  spec.steps = 0;
  expect_error([&] { run(method_or_throw("rk4"), s.bodies[0], s.centres, spec); }, "steps");
  expect_error([] { method_or_throw("rk5"); }, "unknown method 'rk5'");
}

// ---- scene files -------------------------------------------------------------------------------

TEST(SceneFile, ParsesBothBodyForms) {
  const Scene s = parse_scene(R"(
[[centre]]
position = [1.0, 2.0, 0.0]
A = -2
[[centre]]
A = 0.5
[[body]]
name = "thesis"
m = 1
B = 0.7
J = 1
d = 10
L = 200
K1 = 5
Kx = 2
Kz = 5
[[body]]
m = 2
B = 0
J = 1
R = [-50, 3, 0]
v = [1, 0, 0]
w = [0, 0, 1]
)", "inline");
  ASSERT_EQ(s.centres.size(), 2u);
  ASSERT_EQ(s.bodies.size(), 2u);
  EXPECT_EQ(s.centres[0].c, Vec3(1, 2, 0));
  EXPECT_EQ(s.centres[1].c, Vec3::Zero());
  EXPECT_EQ(s.bodies[0].name, "thesis");
  EXPECT_EQ(s.bodies[1].name, "body2");
  EXPECT_NEAR((to_momenta(s.bodies[0].p, s.bodies[0].s0).K1 - Vec3(5, 0, 0)).norm(), 0.0, kConversionTol);
  EXPECT_EQ(s.bodies[1].s0.R, Vec3(-50, 3, 0));
}

TEST(SceneFile, ExampleSceneInRepositoryIsValid) {
  const Scene s = read_scene_file(std::string(BODYPOINT_SOURCE_DIR) + "/scenes/two-centres.toml");
  EXPECT_GE(s.centres.size(), 2u);
  EXPECT_GE(s.bodies.size(), 2u);
}

TEST(SceneFile, RejectsMalformedFiles) {
  const std::string body = "[[body]]\nm = 1\nB = 0\nJ = 1\nR = [1, 0, 0]\nv = [0, 1, 0]\nw = [0, 0, 0]\n";
  expect_error([] { parse_scene("this is = = not toml", "f"); }, "f: line 1");
  // A non-ASCII character where a key is expected (fuzz_scene's find; toml++ 3.3 defect, lib/CMakeLists.txt).
  expect_error([] { parse_scene("[[ceNtre]]\na\xc3\xa6" "2[\nbody]]", "f"); }, "f: line 2");
  expect_error([&] { parse_scene("[[centre]]\nA = -1\ncolour = 3\n" + body, "f"); }, "unknown key 'colour'");
  expect_error([&] { parse_scene("[[centre]]\nposition = [0, 0, 0]\n" + body, "f"); }, "missing 'A'");
  expect_error([&] { parse_scene("[[centre]]\nA = \"big\"\n" + body, "f"); }, "'A' must be a number");
  expect_error([&] { parse_scene("[[centre]]\nA = -1\nposition = [0, 0]\n" + body, "f"); }, "array of 3 numbers");
  expect_error([] { parse_scene("[[centre]]\nA = -1\n[[body]]\nm = 1\nB = 0\nJ = 1\nR = [1, 0, 0]\nv = [0, 1, 0]\nw = [0, 0, 0]\nd = 3\n", "f"); },
               "exactly one form");
  expect_error([] { parse_scene("[[centre]]\nA = -1\n[[body]]\nm = 1\nB = 1\nJ = 1\nR = [1, 0, 0]\nv = [0, 1, 0]\nw = [0, 0, 0]\n", "f"); },
               "D = m J - B^2");
  // The scene as a whole is checked once, where it is run (validate); read_scene_file checks it, in the
  // file's name.
  const std::string on_centre = "[[centre]]\nA = -1\n[[body]]\nm = 1\nB = 0\nJ = 1\nR = [0, 0, 0]\nv = [0, 1, 0]\nw = [0, 0, 0]\n";
  expect_error([&] { validate(parse_scene(on_centre, "f")); }, "starts on centre");
  expect_error([] { validate(parse_scene("", "f")); }, "no Coulomb centre");
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "bodypoint_test_on_centre.toml";
  std::ofstream(file) << on_centre;
  expect_error([&] { read_scene_file(file.string()); }, file.string() + ": body 'body1' starts on centre 1");
  std::filesystem::remove(file);
  expect_error([] { read_scene_file("/nonexistent/scene.toml"); }, "cannot open");
}

}  // namespace
}  // namespace bodypoint
