// Sweep throughput per core (issue #14): trajectory-steps per second of the scalar loop (one `run`
// per member) against the batch kernels (bodypoint/batch.hpp) at every width this CPU runs, on the
// members of a d sweep of the thesis's scene (d = 5, 10, ...; invariants tracked as a sweep does).
// Run: build/bin/bench_batch --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// and compare the items_per_second medians of one run (the ratio is the speed-up per core).
#include "bodypoint/batch.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/run.hpp"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

namespace bodypoint {
namespace {

/// Steps per trajectory: long enough that setting up a batch is noise, short enough for a quick run.
constexpr long kSteps = 20000;
/// Members per benchmark iteration: a multiple of every width (8, 4, 2).
constexpr std::size_t kMembers = 8;

std::vector<Scene> members() {
  std::vector<Scene> v;
  for (std::size_t i = 0; i < kMembers; ++i) {
    SceneParams p;
    p.start.d = 5.0 * static_cast<double>(i + 1);
    v.push_back(thesis_scene(p));
  }
  return v;
}

FixedSteps spec() { return {1e-4, kSteps}; }

void BM_SweepScalar(benchmark::State& st, const std::string& method) {
  const MethodInfo& m = method_or_throw(method);
  const auto scenes = members();
  const FixedSteps rs = spec();
  for (auto _ : st)
    for (const Scene& s : scenes) benchmark::DoNotOptimize(run(m, s.bodies[0], s.centres, rs, RunOptions{}));
  st.SetItemsProcessed(st.iterations() * static_cast<long>(kMembers) * kSteps);
}

void BM_SweepBatch(benchmark::State& st, const std::string& method, std::size_t width) {
  const MethodInfo& m = method_or_throw(method);
  std::vector<batch::Member> all;
  for (const Scene& s : members()) all.push_back({s.bodies[0].p, s.bodies[0].s0, s.centres[0].A});
  const FixedSteps rs = spec();
  for (auto _ : st)
    for (std::size_t i = 0; i < all.size(); i += width) {
      const std::vector<batch::Member> lanes(all.begin() + static_cast<long>(i), all.begin() + static_cast<long>(i + width));
      benchmark::DoNotOptimize(batch::run(m, lanes, rs, width));
    }
  st.SetItemsProcessed(st.iterations() * static_cast<long>(kMembers) * kSteps);
}

const bool registered = [] {
  for (const char* m : {"lp-verlet", "lp-y4", "lp-kl8", "thesis-euler", "thesis-fr4", "rk4"}) {
    benchmark::RegisterBenchmark(("BM_SweepScalar/" + std::string(m)).c_str(), BM_SweepScalar, std::string(m))
        ->Unit(benchmark::kMillisecond);
    for (std::size_t w : batch::widths())
      benchmark::RegisterBenchmark(("BM_SweepBatch/" + std::string(m) + "/w" + std::to_string(w)).c_str(), BM_SweepBatch,
                                   std::string(m), w)
          ->Unit(benchmark::kMillisecond);
  }
  return true;
}();

}  // namespace
}  // namespace bodypoint
