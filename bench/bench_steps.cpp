// Micro-benchmarks: the floor (one force evaluation, one exact drift), one step of every method on
// table 3.1 and on a material point, Boost.Odeint's steppers on the same system, and the far pass per
// radian of spin (BM_FarPass: far-ip at tens of radians per step against the splittings and the peers).
// Counters: time_per_step (seconds, SI-prefixed) and force evaluations per second.
//
//   build/bin/bench_steps --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include "bodypoint/field.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/sweep.hpp"
#include "bodypoint/detail/equations.hpp"
#include "bodypoint/rk/odeint.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/scenes.hpp"
#include "bodypoint/splitting/lie_poisson.hpp"
#include "sweep_tasks.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace bodypoint {
namespace {

namespace sp = splitting;
constexpr long kSteps = 10000;  // steps per benchmark iteration (amortises the run set-up)

void set_counters(benchmark::State& st, long steps, long evals) {
  st.counters["time_per_step"] = benchmark::Counter(static_cast<double>(steps),
                                                    benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  st.counters["evals_per_s"] = benchmark::Counter(static_cast<double>(evals), benchmark::Counter::kIsRate);
}

void BM_ForceEvaluation(benchmark::State& st) {
  const OriginCentre f{-2.0};
  Vec3 R(-200, 9, 0), acc = Vec3::Zero();
  for (auto _ : st) {
    acc += f.force(R);
    R.x() += 1e-3;
    benchmark::DoNotOptimize(acc);
  }
  set_counters(st, static_cast<long>(st.iterations()), static_cast<long>(st.iterations()));
}
BENCHMARK(BM_ForceEvaluation);

template <bool Spin>
void BM_ExactDrift(benchmark::State& st) {
  const NamedScene ns = named_scene("thesis");
  BodyPoint p = ns.scene.bodies.front().p;
  if (!Spin) p.B = 0.0;
  const sp::LiePoissonKernel<OriginCentre, Spin> k(p, OriginCentre{-2.0});
  sp::LieState x = k.initial_state(ns.scene.bodies.front().s0);
  for (auto _ : st) {
    k.drift(x, 1e-3);
    benchmark::DoNotOptimize(x);
  }
  set_counters(st, static_cast<long>(st.iterations()), 0);
}
BENCHMARK(BM_ExactDrift<true>)->Name("BM_ExactDrift/body-point");
BENCHMARK(BM_ExactDrift<false>)->Name("BM_ExactDrift/material-point");

/// Whole steps of a registered method (no invariants, no output): the production loop.
void BM_MethodStep(benchmark::State& st, const std::string& method, const std::string& scene) {
  const NamedScene ns = named_scene(scene);
  const MethodInfo& m = method_or_throw(method);
  // Every method to the same end time: kSteps steps of h, fictitious steps ds = h, or step-size control.
  const Advance spec = to_common_end(m, FixedSteps{1e-3, kSteps}, 1e-10);
  RunOptions quiet;
  quiet.track_invariants = false;
  long steps = 0, evals = 0;
  for (auto _ : st) {
    RunResult r;
    try {
      r = run(m, ns.scene.bodies.front(), ns.scene.centres, spec, quiet);
    } catch (const Error& e) {  // a method that refuses the scene is reported, not fatal for the rest
      st.SkipWithError(e.what());
      return;
    }
    benchmark::DoNotOptimize(r.final.R);
    steps += r.steps;
    evals += r.force_evals;
  }
  set_counters(st, steps, evals);
  st.counters["evals_per_step"] = static_cast<double>(evals) / static_cast<double>(steps);
}

void register_method_benchmarks() {
  for (const MethodInfo& m : methods()) {
    for (const char* scene : {"thesis", "material"}) {
      const NamedScene ns = named_scene(scene);  // a method that refuses the scene (ks: B = 0) is left out
      if (!refusal(m, ns.scene.bodies.front(), ns.scene.centres).empty()) continue;
      benchmark::RegisterBenchmark(("BM_Step/" + std::string(m.name) + "/" + scene).c_str(),
                                   [name = std::string(m.name), scene](benchmark::State& st) {
                                     BM_MethodStep(st, name, scene);
                                   });
    }
  }
}

/// Boost.Odeint steppers called directly on the system (no bodypoint loop around them), kSteps steps
/// from the table 3.1 start per iteration: the same regime as BM_Step. (Stepping one long run instead
/// drifts to |R| ~ 1e4 after millions of steps, where a step costs half as much.)
template <class Stepper>
void BM_OdeintDirect(benchmark::State& st) {
  const NamedScene ns = named_scene("thesis");
  const Body& b = ns.scene.bodies.front();
  long evals = 0;
  EquationsOfMotion<OriginCentre, true> sys{b.p, OriginCentre{-2.0}, &evals};
  for (auto _ : st) {
    Stepper stepper;
    OdeState<double> x = to_ode(b.s0);
    for (long i = 0; i < kSteps; ++i) stepper.do_step(std::ref(sys), x, static_cast<double>(i) * 1e-3, 1e-3);
    benchmark::DoNotOptimize(x);
  }
  set_counters(st, static_cast<long>(st.iterations()) * kSteps, evals);
}
BENCHMARK(BM_OdeintDirect<rk::Rk4>)->Name("BM_OdeintDirect/runge_kutta4");
BENCHMARK(BM_OdeintDirect<boost::numeric::odeint::runge_kutta_dopri5<OdeState<double>>>)
    ->Name("BM_OdeintDirect/runge_kutta_dopri5");
BENCHMARK(BM_OdeintDirect<boost::numeric::odeint::runge_kutta_fehlberg78<OdeState<double>>>)
    ->Name("BM_OdeintDirect/runge_kutta_fehlberg78");

const int registered = (register_method_benchmarks(), 0);

}  // namespace
}  // namespace bodypoint

namespace bodypoint {
namespace {
/// Boost.Odeint's controlled rkf78 driven directly to t = 10 at tol 1e-10 (the loop of odeint's
/// integrate_adaptive), to compare with BM_Step/odeint-rkf78, which runs the same through bodypoint.
void BM_OdeintDirectControlledRkf78(benchmark::State& st) {
  const NamedScene ns = named_scene("thesis");
  const Body& b = ns.scene.bodies.front();
  long evals = 0, steps = 0;
  EquationsOfMotion<OriginCentre, true> sys{b.p, OriginCentre{-2.0}, &evals};
  for (auto _ : st) {
    auto stepper = rk::make_controlled<rk::Rkf78>(1e-10);
    OdeState<double> x = to_ode(b.s0);
    double t = 0, dt = 1e-3;
    while (t < 10.0) {
      if (t + dt > 10.0) dt = 10.0 - t;
      if (stepper.try_step(std::ref(sys), x, t, dt) == boost::numeric::odeint::success) ++steps;
    }
    benchmark::DoNotOptimize(x);
  }
  set_counters(st, steps, evals);
}
BENCHMARK(BM_OdeintDirectControlledRkf78);
}  // namespace
}  // namespace bodypoint

namespace bodypoint {
namespace {
/// The far pass of bench/far_field.py (table 3.1 with Kz = 0.1 and d = 50, to t = 80: the body stays
/// 50 or more from the centre the whole time): one whole run per iteration, fixed steps given as the
/// spin angle per step, or a peer's tolerance per step. Counters: time per radian of spin (the run's
/// time over the angle the spin turns by), force evaluations per radian, and the final state's
/// relative error against the long-double reference.
void BM_FarPass(benchmark::State& st, const std::string& method, double radians_per_step, double tol) {
  SceneParams params;
  params.start.Kz = 0.1;
  params.start.d = 50.0;
  const Scene s = thesis_scene(params);
  const Body& b = s.bodies.front();
  constexpr double kEnd = 80.0;
  const double turned = std::abs(b.p.B) / b.p.D() * to_momenta(b.p, b.s0).K1.norm() * kEnd;
  const MethodInfo& m = method_or_throw(method);
  Advance how = ControlledSteps{0.01, kEnd, tol};
  if (!is_step_controlled(m)) {
    const long n = std::max(1L, std::lround(turned / radians_per_step));
    how = FixedSteps{kEnd / static_cast<double>(n), n};
  }
  static const State ref = reference_state(b, s.centres, kEnd, 1e-18L);
  RunOptions quiet;
  quiet.track_invariants = false;
  RunResult r;
  for (auto _ : st) {
    r = run(m, b, s.centres, how, quiet);
    benchmark::DoNotOptimize(r.final.R);
  }
  st.counters["time_per_radian"] =
      benchmark::Counter(turned, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  st.counters["evals_per_radian"] = static_cast<double>(r.force_evals) / turned;
  st.counters["error"] = std::max((r.final.R - ref.R).norm() / ref.R.norm(), (r.final.v - ref.v).norm() / ref.v.norm());
}

void register_far_pass() {
  struct Case {
    const char* method;
    double radians, tol;
    const char* label;
  };
  const Case cases[] = {{"far-ip", 20.0, 0.0, "20rad"},       {"far-ip", 40.0, 0.0, "40rad"},
                        {"lp-kl6", 2.75, 0.0, "2.75rad"},     {"lp-y4", 2.75, 0.0, "2.75rad"},
                        {"gsl-rk8pd", 0.0, 1e-10, "tol1e-10"}, {"gsl-rk8pd", 0.0, 1e-12, "tol1e-12"},
                        {"odeint-rkf78", 0.0, 1e-10, "tol1e-10"}, {"odeint-rkf78", 0.0, 1e-12, "tol1e-12"}};
  for (const Case& c : cases) {
    if (!find_method(c.method)) continue;  // GSL is optional in the build
    benchmark::RegisterBenchmark((std::string("BM_FarPass/") + c.method + "/" + c.label).c_str(),
                                 [c](benchmark::State& st) { BM_FarPass(st, c.method, c.radians, c.tol); });
  }
}
const int far_pass_registered = (register_far_pass(), 0);

}  // namespace
}  // namespace bodypoint
