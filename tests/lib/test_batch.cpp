// Batch kernels (issue #14): every lane computes the scalar run's bits, for every batch method and
// every width this CPU runs; a diverging lane does not touch the others.
#include "common.hpp"
#include "bodypoint/batch.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/detail/run_parts.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace bodypoint {
namespace {

/// Bitwise equality (NaN equals NaN of the same bits): the batch path claims the scalar bits.
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expect_same(const RunResult& batch, const RunResult& scalar, const std::string& what) {
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(same_bits(batch.final.R[k], scalar.final.R[k])) << what << " R" << k << ": " << batch.final.R[k] << " vs " << scalar.final.R[k];
    EXPECT_TRUE(same_bits(batch.final.v[k], scalar.final.v[k])) << what << " v" << k;
    EXPECT_TRUE(same_bits(batch.final.w[k], scalar.final.w[k])) << what << " w" << k;
  }
  ASSERT_TRUE(batch.invariants && scalar.invariants);
  const InvariantStats &a = *batch.invariants, &b = *scalar.invariants;
  EXPECT_TRUE(same_bits(a.max_rel_dE, b.max_rel_dE)) << what << ": " << a.max_rel_dE << " vs " << b.max_rel_dE;
  EXPECT_TRUE(same_bits(a.max_rel_dK2sq, b.max_rel_dK2sq)) << what;
  EXPECT_TRUE(same_bits(a.max_abs_dK2Q, b.max_abs_dK2Q)) << what;
  EXPECT_TRUE(same_bits(a.min_r_attracting, b.min_r_attracting)) << what;
  EXPECT_TRUE(same_bits(a.max_spin_angle, b.max_spin_angle)) << what << ": " << a.max_spin_angle << " vs " << b.max_spin_angle;
  EXPECT_TRUE(same_bits(a.min_turn_cos, b.min_turn_cos)) << what << ": " << a.min_turn_cos << " vs " << b.min_turn_cos;
  EXPECT_EQ(batch.force_evals, scalar.force_evals) << what;
  EXPECT_EQ(assess(batch).outcome, assess(scalar).outcome) << what;
}

/// Eight different scenes of the thesis: d, L, Kx, A (both signs), B and J vary lane to lane.
std::vector<SceneParams> varied_scenes() {
  std::vector<SceneParams> v;
  for (int i = 0; i < 8; ++i) {
    SceneParams p;
    p.start.d = 5.0 + 7.0 * i;
    p.start.L = 40.0 + 3.0 * i;
    p.start.Kx = -2.0 + 0.5 * i;
    p.A = (i % 3 == 0) ? 1.5 : -2.0 + 0.1 * i;  // attracting and repelling centres
    p.B = 0.3 + 0.05 * i;
    p.J = 1.0 + 0.1 * i;
    v.push_back(p);
  }
  return v;
}

FlatRun spec_of(double h, long steps) {
  FlatRun s;
  s.h = h;
  s.steps = steps;
  s.t_end = h * static_cast<double>(steps);
  s.track_invariants = true;
  return s;
}

TEST(Batch, EveryLaneEqualsTheScalarRunBitForBit) {
  const FlatRun spec = spec_of(2e-3, 3000);
  const auto scenes = varied_scenes();
  int methods_run = 0;
  for (const MethodInfo& m : methods()) {
    const Scene probe = thesis_scene(scenes[0]);
    if (!batch::accepts(m, probe.bodies[0], probe.centres)) continue;
    ++methods_run;
    for (std::size_t width : batch::widths()) {
      std::vector<batch::Member> members;
      std::vector<RunResult> scalar;
      for (std::size_t i = 0; i < width - 1; ++i) {  // one lane short of full: the padding path too
        const Scene s = thesis_scene(scenes[i % scenes.size()]);
        members.push_back({s.bodies[0].p, s.bodies[0].s0, s.centres[0].A});
        scalar.push_back(run(m, s.bodies[0], s.centres, spec));
      }
      const auto lanes = batch::run(m, members, std::get<FixedSteps>(flat_advance(m, spec)), width);
      ASSERT_EQ(lanes.size(), members.size());
      for (std::size_t i = 0; i < lanes.size(); ++i)
        expect_same(lanes[i], scalar[i], std::string(m.name) + " width " + std::to_string(width) + " lane " + std::to_string(i));
    }
  }
  // Every table the thesis and Lie-Poisson families list (catalogue.hpp) has its batch kernel, and rk4.
  int expected = 1;
  for (const MethodInfo& m : methods()) expected += m.family == Family::Thesis || m.family == Family::LiePoisson;
  EXPECT_EQ(methods_run, expected) << "rk4 and every thesis and Lie-Poisson method";
}

TEST(Batch, ADivergingLaneLeavesTheOthersAlone) {
  // thesis-euler at h = 0.05 from d = 0.3 next to an attracting centre: the energy error explodes
  // (status diverged or collision); its neighbours are ordinary runs.
  const FlatRun spec = spec_of(0.05, 2000);
  const MethodInfo& m = method_or_throw("thesis-euler");
  SceneParams bad;
  bad.A = 3.0;
  bad.start.d = 0.3;
  bad.start.L = 1.0;
  std::vector<SceneParams> ps = varied_scenes();
  ps[1] = bad;
  for (std::size_t width : batch::widths()) {
    std::vector<batch::Member> members;
    std::vector<RunResult> scalar;
    for (std::size_t i = 0; i < width; ++i) {
      const Scene s = thesis_scene(ps[i % ps.size()]);
      members.push_back({s.bodies[0].p, s.bodies[0].s0, s.centres[0].A});
      scalar.push_back(run(m, s.bodies[0], s.centres, spec));
    }
    ASSERT_NE(assess(scalar[1]).outcome, Outcome::ok) << "the test needs a lane that fails";
    const auto lanes = batch::run(m, members, std::get<FixedSteps>(flat_advance(m, spec)), width);
    for (std::size_t i = 0; i < width; ++i) expect_same(lanes[i], scalar[i], "lane " + std::to_string(i));
  }
}

TEST(Batch, ScenesWithoutABatchKernelAreDeclined) {
  const Scene s = thesis_scene(SceneParams{});
  EXPECT_FALSE(batch::accepts(method_or_throw("ab4"), s.bodies[0], s.centres));
  EXPECT_FALSE(batch::accepts(method_or_throw("logh-kl6"), s.bodies[0], s.centres));
  SceneParams material;
  material.B = 0.0;
  const Scene point = thesis_scene(material);
  EXPECT_FALSE(batch::accepts(method_or_throw("lp-y4"), point.bodies[0], point.centres)) << "B = 0 runs the spin-free scalar kernel";
  SceneParams code;
  code.law = ForceLaw::thesis_code;
  const Scene published = thesis_scene(code);
  EXPECT_FALSE(batch::accepts(method_or_throw("thesis-fr4"), published.bodies[0], published.centres));
  EXPECT_THROW(batch::run(method_or_throw("ab4"), {{s.bodies[0].p, s.bodies[0].s0, -2.0}}, FixedSteps{1e-3, 10}), Error);
  EXPECT_THROW(batch::run(method_or_throw("lp-y4"), std::vector<batch::Member>(batch::width() + 1, {s.bodies[0].p, s.bodies[0].s0, -2.0}),
                          FixedSteps{1e-3, 10}), Error);
}

TEST(Batch, ABatchStopsWhenItsCancellationIsSet) {
  // A batch polls the run's cancellation as the scalar loops do (every kPollStride steps): set, it
  // stops within one stride and returns no result; unset, it runs to the end. Every kernel kind, every width.
  const Scene s = thesis_scene(SceneParams{});
  const std::vector<batch::Member> members(2, {s.bodies[0].p, s.bodies[0].s0, s.centres[0].A});
  std::atomic<bool> stop{true}, go{false};
  for (const char* name : {"lp-y4", "thesis-fr4", "rk4"})
    for (std::size_t width : batch::widths()) {
      const MethodInfo& m = method_or_throw(name);
      EXPECT_TRUE(batch::run(m, members, FixedSteps{1e-4, 100 * kPollStride}, width, &stop).empty()) << name;
      const auto done = batch::run(m, members, FixedSteps{1e-4, 100 * kPollStride}, width, &go);
      EXPECT_EQ(done[0].steps, 100 * kPollStride) << name;
      EXPECT_TRUE(done[0].final.R.allFinite()) << name;
    }
}

}  // namespace
}  // namespace bodypoint
