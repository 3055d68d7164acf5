// Reliability, fourth pass (issue #56): no scattering answer without an encounter, no broken companion
// taken for "no estimate", no lost standard output, no right answer refused by the accuracy mode.
#include "cli_helpers.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <chrono>
#include <csignal>
#include <regex>
#include <thread>
#include <string>
#include <sys/wait.h>

namespace bodypoint {
namespace {

namespace fs = std::filesystem;
using test::run_cli;

/// The number after `"key": ` in simulate --json's output (NaN when absent).
double json_number(const std::string& json, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(json, m, std::regex("\"" + key + "\": ([-+0-9.eE]+|NaN|null)"))) return std::nan("");
  return m[1] == "null" || m[1] == "NaN" ? std::nan("") : std::stod(m[1]);
}

/// Table 3.1's guiding centre drifts along K1 (towards the centre) only above K1 = B Kx/J = 0.7 * 2 / 1.
constexpr double kDriftZeroK1 = 1.4;
/// The speed at infinity solved for and measured back on the run's incoming asymptote agree to round-off
/// (secant iterations to 1e-14 in K1).
constexpr double kSolvedVInf = 1e-12;

TEST(FourthPass, SpeedAtInfinityTakesTheRootWithAnEncounter) {
  // v_inf below 2 had two roots; the one below the drift's zero drifts away (K1 = 0.884 for v_inf = 1).
  for (const char* v : {"1", "0.3"}) {
    const auto r = run_cli(std::string("simulate --tol 1e-8 --scattering --v-inf ") + v);
    ASSERT_EQ(r.code, 0) << v << ": " << r.err;
    std::smatch k1;
    ASSERT_TRUE(std::regex_search(r.out, k1, std::regex(" K1=([0-9.e+-]+)"))) << r.out;
    EXPECT_GT(std::stod(k1[1]), kDriftZeroK1) << r.out;
    EXPECT_NE(r.out.find("K1 above 1.4 where the guiding centre approaches"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("no closest approach"), std::string::npos) << r.out;
    const auto j = run_cli(std::string("simulate --json --tol 1e-8 --scattering --v-inf ") + v);
    ASSERT_EQ(j.code, 0) << j.err;
    EXPECT_NEAR(json_number(j.out, "v_inf_in"), std::stod(v), kSolvedVInf) << j.out;
  }
  // A start that drifts away has no encounter: no deflection is reported, and no b solves it.
  const auto away = run_cli("simulate --json --tol 1e-8 --scattering --K1 0.8");
  EXPECT_NE(away.code, 0) << away.out;
  EXPECT_NE(away.err.find("no encounter happened"), std::string::npos) << away.err;
  test::expect_refused("simulate --tol 1e-8 --scattering --K1 0.8 ", {{"--b 5", "drifts away from the centre"}});
}

TEST(FourthPass, ACompanionThatBreaksDownFlagsTheRun) {
  // scenes/two-centres.toml's material body alone: at ds = 3 ttl-s4 ended at R = (-1.8e9, 1.3e8, 0)
  // where the answer is (148.9, 0.78, 0); its companion at ds/2 failed and the run read ok.
  const fs::path scene = test::temp_path("material.toml");
  std::ofstream(scene) << "[[centre]]\nposition = [0.0, 0.0, 0.0]\nA = -2.0\n[[centre]]\nposition = [40.0, 6.0, 0.0]\n"
                          "A = -1.0\n[[body]]\nm = 1.0\nB = 0.0\nJ = 1.0\nR = [-150.0, 3.0, 0.0]\nv = [5.0, 0.0, 0.0]\n"
                          "w = [0.0, 0.0, 0.0]\n";
  const auto r = run_cli("simulate --method ttl-s4 --h 3 --t-end 60 --scene " + scene.string());
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_NE(r.err.find("broke down"), std::string::npos) << r.err;
  // The same run at a step its companion gets through is ok, with its estimate.
  const auto fine = run_cli("simulate --json --method ttl-s4 --h 0.05 --t-end 60 --scene " + scene.string());
  ASSERT_EQ(fine.code, 0) << fine.err;
  EXPECT_TRUE(std::isfinite(json_number(fine.out, "err_estimate"))) << fine.out;
}

TEST(FourthPass, ARunOfAFewStepsIsBoundedByASecondCompanion) {
  // ttl-verlet and logh-verlet at ds = 1 and 0.5 on the material pass take 1 step: 2.1e-5 off, estimated
  // 4.0e-6 and 5.0e-6 from a companion of 2 steps (the estimate ladder's low estimates).
  for (const char* args : {"--method ttl-verlet --h 1", "--method ttl-verlet --h 0.5", "--method logh-verlet --h 0.5"}) {
    const auto r = run_cli(std::string("simulate --json --B 0 --t-end 20 --reference ") + args);
    ASSERT_EQ(r.code, 0) << args << ": " << r.err;
    EXPECT_GE(json_number(r.out, "err_estimate"), json_number(r.out, "err_rel")) << args;
  }
}

TEST(FourthPass, AFlaggedRunWhoseDifferencesFallIsKeptWithItsBound) {
  // lp-rkn6 at h = 0.1, B = 0.95 (4.87 rad of spin per step) was refused at an error of 4.8e-7: its
  // companions' differences fall 2.8x where order 6 asks 8x. Kept, with an estimate that bounds the error.
  const auto kept = run_cli("simulate --json --method lp-rkn6 --h 0.1 --B 0.95 --t-end 20 --reference");
  ASSERT_EQ(kept.code, 0) << kept.err;
  EXPECT_GE(json_number(kept.out, "err_estimate"), json_number(kept.out, "err_rel"));
  // Runs that alias the spin, whose finer pairs differ more than the coarse one, stay refused
  // (kep-ss10 at h = 0.5 on B = 0.9 is 9.5 % off, its companions 0.4 % apart).
  test::expect_refused("simulate --B 0.9 --d 3 --t-end 40 ", {{"--method kep-ss10 --h 0.5", "not resolved"}});
}

TEST(FourthPass, StandardOutputIsCheckedLikeAFile) {
  const fs::path err = test::temp_path("full.err");
  for (const char* args : {"simulate --json", "simulate", "methods", "--version",
                           "sweep --param d --from 5 --to 10 --step 5 --methods lp-y4 --steps 100"}) {
    // CI=1: on a busy machine a command past 2 s adds its "working" line to the one counted here.
    const std::string cmd = "CI=1 " + std::string(BODYPOINT_BIN) + " " + args + " >/dev/full 2>" + err.string() + " </dev/null";
    const int status = std::system(cmd.c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << args;
    const std::string said = test::read(err);
    EXPECT_NE(said.find("standard output could not be written"), std::string::npos) << args << ": " << said;
    EXPECT_EQ(std::count(said.begin(), said.end(), '\n'), 1) << said;
  }
  // A pipe its reader closed ends the command as it ends every filter: by SIGPIPE, without a word.
  const std::string piped = std::string(BODYPOINT_BIN) + " methods 2>" + err.string() + " | head -c 1 >/dev/null";
  ASSERT_EQ(std::system(piped.c_str()), 0);
  EXPECT_EQ(test::read(err), "");
}

/// The search's force evaluations over its delivered run's: the pilot pair, its halvings while the pair
/// is no trajectory yet (at most the last pair's cost), the ladder and the companion (measured: 3.3-4.5x).
constexpr double kSearchOverDelivered = 6.0;

TEST(FourthPass, Rk4UnderTolDelivers) {
  // Each was refused: "out of reach within 2e9 force evaluations (last estimate nan)", "the step the
  // search needs (0.000000) is too small", or 48 s of search.
  for (const char* args : {"--t-end 20 --tol 1e-4", "--tol 1e-4", "--A 2 --d 3 --tol 1e-4", "--d 5 --tol 1e-6"}) {
    const auto r = run_cli(std::string("simulate --json --method rk4 --reference ") + args);
    ASSERT_EQ(r.code, 0) << args << ": " << r.err;
    const double tol = json_number(r.out, "tol");
    EXPECT_LE(json_number(r.out, "err_rel"), tol) << args;
    EXPECT_LE(json_number(r.out, "err_estimate"), tol) << args;
    EXPECT_LE(json_number(r.out, "search_force_evals"), kSearchOverDelivered * json_number(r.out, "force_evals")) << args;
  }
}

/// A material point given by (b, v_inf) is the same hyperbola from any start distance: its runs from L and
/// 2L differ by their numerical errors and the solves of d and K1 (relative 1e-14), far below this.
constexpr double kSameHyperbola = 1e-8;

TEST(FourthPass, ScatteringStatesItsStartDistanceError) {
  // At B = 0.7, b = 1, arrival phase 1 the deflection converges as 1/L (0.0900936, 0.0901056, 0.0901116,
  // 0.0901147 from L = 200 .. 1600): the run at L = 200 stated a model error of 2e-8 for a distance of
  // 2.4e-5 from the limit. The limit lies within the stated error of the run at L = 1600; the run at 200
  // must state at least its distance to that run plus that run's own error.
  const std::string args = "simulate --json --tol 1e-10 --scattering --B 0.7 --b 1 --arrival-phase 1 --L ";
  const auto near = run_cli(args + "200"), far = run_cli(args + "1600");
  ASSERT_EQ(near.code, 0) << near.err;
  ASSERT_EQ(far.code, 0) << far.err;
  const double theta = json_number(near.out, "deflection"), theta_far = json_number(far.out, "deflection");
  const double error = json_number(near.out, "deflection_error"), error_far = json_number(far.out, "deflection_error");
  EXPECT_GE(json_number(near.out, "start_distance_error"), 0.0);
  EXPECT_LE(std::abs(theta - theta_far) + error_far, error) << near.out;
  EXPECT_GT(json_number(near.out, "time_delay_error"), 0.0);
  // The run from 2L is work done for this answer: it is in the count (issue #79: it was left out).
  const double far_evals = json_number(near.out, "start_distance_force_evals");
  EXPECT_GT(far_evals, 0.0) << near.out;
  EXPECT_GE(json_number(near.out, "total_force_evals"), far_evals + json_number(near.out, "force_evals")) << near.out;
  // A material point given by b has K1 as its momentum at infinity (speed_at_infinity_of), so its hyperbola
  // does not depend on where it starts: its runs from L = 200 and 1600 agree within their stated errors, and
  // the start distance adds nothing (with K1 at the start its speed at infinity moved with L, and the
  // deflection 2.5e-4 with it at b = 0.5). Given its v_inf as well, the same. A scene file's states have no L.
  const std::string material_args = "simulate --json --tol 1e-10 --scattering --B 0 --b 1 --L ";
  const auto material = run_cli(material_args + "200"), material_far = run_cli(material_args + "1600");
  ASSERT_EQ(material.code, 0) << material.err;
  ASSERT_EQ(material_far.code, 0) << material_far.err;
  EXPECT_EQ(json_number(material.out, "start_distance_error"), 0.0) << material.out;
  EXPECT_LE(std::abs(json_number(material.out, "deflection") - json_number(material_far.out, "deflection")),
            json_number(material.out, "deflection_error") + json_number(material_far.out, "deflection_error"))
      << material.out;
  const auto at_v_inf = run_cli("simulate --json --tol 1e-10 --scattering --B 0 --b 1 --v-inf 5");
  ASSERT_EQ(at_v_inf.code, 0) << at_v_inf.err;
  EXPECT_LT(json_number(at_v_inf.out, "start_distance_error"), kSameHyperbola) << at_v_inf.out;
  const fs::path scene = test::temp_path("spinning.toml");
  std::ofstream(scene) << "[[centre]]\nposition = [0.0, 0.0, 0.0]\nA = -2.0\n[[body]]\nm = 1.0\nB = 0.7\nJ = 1.0\nd = 10.0\n"
                          "L = 200.0\nK1 = 5.0\nKx = 2.0\nKz = 5.0\n";
  const auto file = run_cli("simulate --json --tol 1e-8 --scattering --scene " + scene.string());
  ASSERT_EQ(file.code, 0) << file.err;
  // Its observables are its trajectory's (issue #79: a scene given by its states keeps its meaning), so the
  // start distance adds nothing and the deflection has its total error.
  EXPECT_EQ(json_number(file.out, "start_distance_error"), 0.0) << file.out;
  EXPECT_TRUE(std::isfinite(json_number(file.out, "deflection_error"))) << file.out;
  EXPECT_NE(file.out.find("the scene file gives states"), std::string::npos);
}

TEST(FourthPass, MessagesNameTheQuantity) {
  const fs::path phase = test::temp_path("phase.toml"), far = test::temp_path("far.toml");
  const std::string body = "[[body]]\nm = 1.0\nB = 0.7\nJ = 1.0\nd = 10.0\nL = 200.0\nK1 = 5.0\nKx = 2.0\nKz = 5.0\n";
  std::ofstream(phase) << "[[centre]]\nposition = [0.0, 0.0, 0.0]\nA = -2.0\n" << body << "phase = nan\n";
  std::ofstream(far) << "[[centre]]\nposition = [1e308, 0.0, 0.0]\nA = -2.0\n" << body;
  test::expect_refused("simulate --steps 10 ", {
      {"--scene " + phase.string(), "body 1: phase must be a finite number"},        // was "R must be ..."
      {"--scene " + far.string(), "the square of that distance overflows a double"},  // was "reduce --h"
  });
  // A subnormal is a number: a plane whose normal's length underflows is a plane (was "not a finite number").
  const auto plane = run_cli("simulate --json --steps 10 --event plane=1e-320,0,0,0");
  EXPECT_EQ(plane.code, 0) << plane.err;
  const auto x = run_cli("simulate --json --steps 10 --event x=1e-320");
  EXPECT_EQ(x.code, 0) << x.err;
}

TEST(FourthPass, ASignalThatEndsTheProcessSaysSo) {
  // SIGINT outside a sweep's rows (a large grid being checked, a long simulate) exited 130 without a word.
  const fs::path dir = test::temp_path("signal");
  fs::create_directories(dir);
  const pid_t pid = test::spawn({"simulate", "--steps", "200000000", "--every", "1000", "--quiet", "--no-error-estimate",
                                 "--out", (dir / "traj.csv").string()},
                                dir / "err.txt");
  ASSERT_GT(pid, 0);
  // The run holds its lock while it writes: then the handler is installed and the run under way.
  for (int i = 0; i < 200 && test::leftovers(dir, "traj.csv.lock").empty(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT);
  EXPECT_NE(test::read(dir / "err.txt").find("interrupted by signal 2"), std::string::npos) << test::read(dir / "err.txt");
}

}  // namespace
}  // namespace bodypoint
