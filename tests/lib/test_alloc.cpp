// No heap allocation inside any step loop: a counting global operator new shows that the number of
// allocations of a run does not depend on its number of steps, for every method, with and without
// invariant tracking, with one centre and with several.
#include "common.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/scenes.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace bodypoint {
namespace {

long allocations_of(const MethodInfo& m, const NamedScene& ns, long steps, bool track) {
  FlatRun spec;
  spec.h = 1e-3;
  spec.steps = steps;
  spec.t_end = 1e-3 * static_cast<double>(steps);
  spec.track_invariants = track;
  const long before = g_allocations.load();
  const RunResult r = run(m, ns.scene.bodies.front(), ns.scene.centres, spec);
  EXPECT_TRUE(r.final.R.allFinite());
  return g_allocations.load() - before;
}

TEST(Allocation, NoneInsideAnyStepLoop) {
  for (const char* scene : {"thesis", "material", "two-centres"}) {
    const NamedScene ns = named_scene(scene);
    for (const MethodInfo& m : methods()) {
      // Boost.Odeint's bulirsch_stoer keeps its extrapolation tables in std::vector and resizes them
      // when it changes order: the competitor's own code, measured as it ships.
      if (m.name == "odeint-bs") continue;
      if (!refusal(m, ns.scene.bodies.front(), ns.scene.centres).empty()) continue;  // ks: B = 0, one centre
      for (bool track : {false, true}) {
        const long few = allocations_of(m, ns, 100, track);
        const long many = allocations_of(m, ns, 10000, track);
        EXPECT_EQ(few, many) << m.name << " on " << scene << (track ? " with invariants" : "");
      }
    }
  }
}

}  // namespace
}  // namespace bodypoint
