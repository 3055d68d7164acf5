// bodypoint: picks the batch width the CPU runs and converts between the program's types and the
// per-width units' plain arrays (detail/batch_abi.hpp).
#include "bodypoint/batch.hpp"

#include "bodypoint/detail/batch_abi.hpp"
#include "bodypoint/splitting/lie_poisson.hpp"

#include <chrono>
#include <cstdlib>
#include <string>

BODYPOINT_BATCH_DECLARE(w2)
#ifdef BODYPOINT_BATCH_HAVE_W4
BODYPOINT_BATCH_DECLARE(w4)
#endif
#ifdef BODYPOINT_BATCH_HAVE_W8
BODYPOINT_BATCH_DECLARE(w8)
#endif

namespace bodypoint::batch {

void abi::scalar_drift_functions(double x, double* out) {
  const splitting::DriftFunctions f = splitting::drift_functions(x);
  out[0] = f.S1;
  out[1] = f.C1;
  out[2] = f.S3;
}

namespace {

struct Isa {
  std::size_t width;
  const char* name;
  bool (*supports)(int);
  long (*run)(int, const double*, std::size_t, double, long, double*, abi::Poll, const void*);
};

/// The units this CPU runs, widest first.
const std::vector<Isa>& runnable() {
  static const std::vector<Isa> units = [] {
    std::vector<Isa> u;
#ifdef BODYPOINT_BATCH_HAVE_W8
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq")) u.push_back({8, "avx512", w8::supports, w8::run});
#endif
#ifdef BODYPOINT_BATCH_HAVE_W4
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) u.push_back({4, "avx2", w4::supports, w4::run});
#endif
    u.push_back({2, "sse2", w2::supports, w2::run});
    return u;
  }();
  return units;
}

/// The unit of exactly `width` lanes, or the widest no wider than BODYPOINT_SIMD when width = 0.
const Isa& unit(std::size_t width) {
  if (width == 0) {
    const char* env = std::getenv("BODYPOINT_SIMD");
    const long cap = env ? std::atol(env) : 64;
    for (const Isa& u : runnable())
      if (static_cast<long>(u.width) <= cap) return u;
    return runnable().back();
  }
  for (const Isa& u : runnable())
    if (u.width == width) return u;
  throw Error("no batch unit of " + std::to_string(width) + " lanes runs on this CPU");
}

const Isa& isa_in_use() {
  static const Isa& chosen = unit(0);
  return chosen;
}

}  // namespace

std::size_t width() { return isa_in_use().width; }
std::vector<std::size_t> widths() {
  std::vector<std::size_t> w;
  for (const Isa& u : runnable()) w.push_back(u.width);
  return w;
}
const char* isa() { return isa_in_use().name; }

bool accepts(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres) {
  return isa_in_use().supports(method.batch_kernel) && body.p.B != 0.0 && centres.size() == 1 &&
         centres.front().c.isZero(0.0) && centres.front().law == ForceLaw::coulomb;
}

std::vector<RunResult> run(const MethodInfo& method, const std::vector<Member>& members, const FixedSteps& spec,
                           std::size_t width, const std::atomic<bool>* cancel) {
  const Isa& isa = width == 0 ? isa_in_use() : unit(width);
  if (!isa.supports(method.batch_kernel)) throw Error(method.name + " has no batch kernel");
  if (members.empty() || members.size() > isa.width)
    throw Error("a batch holds 1 to " + std::to_string(isa.width) + " members, got " + std::to_string(members.size()));
  std::vector<double> in(members.size() * abi::kIn), out(members.size() * abi::kOut);
  for (std::size_t i = 0; i < members.size(); ++i) {
    const Member& m = members[i];
    double* x = in.data() + i * abi::kIn;
    x[0] = m.p.m, x[1] = m.p.B, x[2] = m.p.J, x[3] = m.A;
    for (int k = 0; k < 3; ++k) x[4 + k] = m.s0.R[k], x[7 + k] = m.s0.v[k], x[10 + k] = m.s0.w[k];
  }
  const auto t0 = std::chrono::steady_clock::now();
  const abi::Poll poll = [](const void* flag) { return static_cast<const std::atomic<bool>*>(flag)->load(std::memory_order_relaxed); };
  const long evals = isa.run(method.batch_kernel, in.data(), members.size(), spec.h, spec.steps, out.data(),
                             cancel != nullptr ? poll : nullptr, cancel);
  if (evals == abi::kStopped) return {};
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::vector<RunResult> results(members.size());
  for (std::size_t i = 0; i < members.size(); ++i) {
    const double* o = out.data() + i * abi::kOut;
    RunResult& r = results[i];
    r.final = State{Vec3(o[0], o[1], o[2]), Vec3(o[3], o[4], o[5]), Vec3(o[6], o[7], o[8])};
    r.steps = spec.steps;
    r.t_end = static_cast<double>(spec.steps) * spec.h;
    r.force_evals = evals;
    r.wall_s = wall / static_cast<double>(members.size());
    InvariantStats st;
    st.max_rel_dE = o[9];
    st.max_rel_dK2sq = o[10];
    st.max_abs_dK2Q = o[11];
    st.has_K2Q = true;
    st.min_r_attracting = o[12];
    st.r0_attracting = o[13];
    st.max_spin_angle = o[14];
    st.min_turn_cos = o[15];
    r.invariants = st;
  }
  return results;
}

}  // namespace bodypoint::batch
