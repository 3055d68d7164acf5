// bodypoint: the batch kernels for one vector width (BODYPOINT_BATCH_W lanes), compiled once per
// width with its -m flags (lib/CMakeLists.txt); batch.cpp picks the widest the CPU runs.
//
// Each kernel is the scalar kernel's arithmetic on W bodies at once: the Lie-Poisson kernel
// (splitting/lie_poisson.hpp, spin on), the thesis's kernel (splitting/thesis.hpp, spin on, no code
// slip) and odeint's classical RK4 (its generic Runge-Kutta stages, zero coefficients included) on
// the equations of motion (rhs.hpp), all in a field of one Coulomb centre at the origin, driven by the
// same composition engine (splitting/composition.hpp) and observed by the scalar monitor's arithmetic.
//
// This unit is compiled with wider instruction sets than the rest of the program, so it calls no
// inline function of a header (Eigen, the standard library, splitting's scalar code): the linker
// could keep its wide copy for every caller. Everything it runs is its own (internal linkage) or
// constexpr data; it exchanges plain arrays (detail/batch_abi.hpp) with batch.cpp, built for the baseline.
#include "bodypoint/batch/lanes.hpp"

#include "bodypoint/detail/batch_abi.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/splitting/catalogue.hpp"
#include "bodypoint/splitting/lie_poisson.hpp"
#include "bodypoint/detail/run_parts.hpp"

#include <limits>
#include <string_view>

namespace bodypoint::batch::BODYPOINT_BATCH_NS {
namespace {

namespace sp = splitting;

/// Per-lane constants of the bodies and the centre.
struct Params {
  Lane m, B, J, A, inv_D;
};

/// Lane k of member field f: members[k * kIn + f], the last member repeated to fill the lanes.
Lane lane_of(const double* in, std::size_t count, std::size_t f) {
  Lane v;
  for (std::size_t i = 0; i < W; ++i) v[i] = in[(i < count ? i : count - 1) * abi::kIn + f];
  return v;
}
V3 v3_of(const double* in, std::size_t count, std::size_t f) {
  return {lane_of(in, count, f), lane_of(in, count, f + 1), lane_of(in, count, f + 2)};
}
void put(const V3& v, std::size_t i, double* out) {
  out[0] = v.x[i];
  out[1] = v.y[i];
  out[2] = v.z[i];
}

/// OriginCentre::force: (-A inv_r inv_r inv_r) R.
V3 force(const Params& p, const V3& R) {
  const Lane inv_r = 1.0 / vsqrt(squared_norm(R));
  return (-p.A * inv_r * inv_r * inv_r) * R;
}

/// A physical state of every lane.
struct Physical {
  V3 R, v, w;
};

/// InvariantMonitor's arithmetic (invariants.hpp) for one centre at the origin.
class Monitor {
 public:
  Monitor(const Params& p, const Physical& s0, double h) : p_(p), h_(h), prev_R_(s0.R) {
    E0_ = energy(s0);
    K2sq0_ = squared_norm(K2(s0));
    K2Q0_ = K2Q(s0);
    r0_ = min_r_ = nearest(s0.R);
    max_dE_ = max_dK2sq_ = max_dK2Q_ = max_spin_ = splat(0.0);
    min_cos_ = splat(1.0);
    spin_rate_per_K1_ = vabs(p.B) * (1.0 / (p.m * p.J - p.B * p.B));
  }

  /// The state that ends a step of h: InvariantMonitor::step's arithmetic.
  void step(const Physical& s) {
    max_dE_ = max_keeping_nan(max_dE_, relative_deviation(energy(s), E0_));
    max_dK2sq_ = max_keeping_nan(max_dK2sq_, relative_deviation(squared_norm(K2(s)), K2sq0_));
    max_dK2Q_ = max_keeping_nan(max_dK2Q_, vsqrt(squared_norm(K2Q(s) - K2Q0_)));
    const Lane r = nearest(s.R);
    min_r_ = r < min_r_ ? r : min_r_;  // std::min(so_far, r)
    const Lane angle = spin_rate_per_K1_ * vsqrt(squared_norm(p_.m * s.v + p_.B * s.w)) * h_;
    max_spin_ = max_keeping_nan(max_spin_, angle);
    const Lane q = squared_norm(prev_R_) * squared_norm(s.R);
    const Lane c = q > 0.0 ? dot(prev_R_, s.R) / vsqrt(q) : splat(1.0);  // turn_cos (field.hpp)
    const Lane turned = p_.A != 0.0 ? c : splat(1.0);
    min_cos_ = turned < min_cos_ ? turned : min_cos_;
    prev_R_ = s.R;
  }

  /// max |dE|/|E0|, max |dK2^2|/K2^2_0, max |dK2Q|, closest and first distance to the centre, largest
  /// spin angle of a step, smallest cosine of a step's turn about the centre.
  void stats(std::size_t i, double* out) const {
    out[0] = max_dE_[i];
    out[1] = max_dK2sq_[i];
    out[2] = max_dK2Q_[i];
    out[3] = min_r_[i];
    out[4] = r0_[i];
    out[5] = max_spin_[i];
    out[6] = min_cos_[i];
  }

 private:
  Lane energy(const Physical& s) const {
    const Lane kinetic = 0.5 * p_.m * squared_norm(s.v) + p_.B * dot(s.v, s.w) + 0.5 * p_.J * squared_norm(s.w);
    return kinetic + -p_.A / vsqrt(squared_norm(s.R));
  }
  V3 K2(const Physical& s) const { return p_.B * s.v + p_.J * s.w; }
  V3 K2Q(const Physical& s) const { return cross(s.R, p_.m * s.v + p_.B * s.w) + K2(s); }
  Lane nearest(const V3& R) const {
    return p_.A > 0.0 ? vsqrt(squared_norm(R)) : splat(std::numeric_limits<double>::infinity());
  }
  static Lane relative_deviation(Lane x, Lane x0) {
    const Lane scale = vabs(x0);
    return scale > 0.0 ? vabs(x - x0) / scale : vabs(x - x0);
  }
  static Lane max_keeping_nan(Lane so_far, Lane x) {
    const Lane nan = splat(std::numeric_limits<double>::quiet_NaN());
    const Lane m = so_far < x ? x : so_far;
    return (so_far != so_far) || (x != x) ? nan : m;
  }

  Params p_;
  double h_;
  Lane E0_, K2sq0_, r0_, min_r_, max_dE_, max_dK2sq_, max_dK2Q_, max_spin_, min_cos_, spin_rate_per_K1_;
  V3 K2Q0_, prev_R_;
};

/// The run's cancellation: polled every kPollStride steps (run.hpp), as the scalar loops poll theirs.
/// True after step i when the run goes on; false when its Poll said stop (the runner returns abi::kStopped).
struct Canceller {
  abi::Poll poll = nullptr;
  const void* context = nullptr;
  bool operator()(long i) const { return poll == nullptr || i % kPollStride != 0 || !poll(context); }
};

/// The engine's observer: the physical state of every step, to the monitor; the engine's poll.
template <class Kernel>
struct Observer {
  static constexpr bool active = true;
  const Kernel& kernel;
  Monitor& monitor;
  Canceller cancel;
  template <class X>
  void operator()(long, const X& x) {
    monitor.step(kernel.to_physical(x));
  }
  bool stopped = false;  ///< the Poll said stop: the loop ended early
  bool poll(long i) { return cancel(i) || !(stopped = true); }
};

// --- the Lie-Poisson kernel (splitting::LiePoissonKernel<OriginCentre, true>) ---------------------

struct LieLanes {
  V3 R, K1, K2, R_err, K1_err;
  Lane K2sq0, half_inv_K2sq0;
};

/// splitting::drift_functions lane by lane: the 4-term series for every lane at once when all are in
/// its range (every drift of the studies: phi = |Omega| tau ~ 1e-4), the scalar function otherwise.
void drift_functions(Lane x, Lane& S1, Lane& C1, Lane& S3) {
  if (all(x < 1e-3)) {
    const auto& c = sp::detail::kSeries;
    S1 = splat(c.s1[3]);
    C1 = splat(c.c1[3]);
    S3 = splat(c.s3[3]);
    for (int k = 2; k >= 0; --k) {
      S1 = S1 * x + c.s1[k];
      C1 = C1 * x + c.c1[k];
      S3 = S3 * x + c.s3[k];
    }
    return;
  }
  for (std::size_t i = 0; i < W; ++i) {
    double f[3];
    abi::scalar_drift_functions(x[i], f);
    S1[i] = f[0];
    C1[i] = f[1];
    S3[i] = f[2];
  }
}

struct LieKernel {
  using state_type = LieLanes;
  static constexpr bool mergeable = true;
  Params p;
  long evals = 0;

  LieLanes initial_state(const Physical& s) const {
    LieLanes x;
    x.R = s.R;
    x.K1 = p.m * s.v + p.B * s.w;
    x.K2 = p.B * s.v + p.J * s.w;
    x.R_err = x.K1_err = V3{splat(0.0), splat(0.0), splat(0.0)};
    x.K2sq0 = squared_norm(x.K2);
    x.half_inv_K2sq0 = x.K2sq0 > 0.0 ? 0.5 / x.K2sq0 : splat(0.0);
    return x;
  }
  void begin_step(LieLanes&) const {}
  void drift(LieLanes& x, double tau) const {
    const Lane BD = p.B * p.inv_D;
    const V3 Omega = (-BD) * x.K1;
    const V3 u = cross(Omega, x.K2);
    const V3 Wv = cross(Omega, u);
    Lane S1, C1, S3;
    drift_functions(squared_norm(Omega) * tau * tau, S1, C1, S3);
    const double t2 = tau * tau;
    const V3 dR = (tau * p.inv_D) * (p.J * x.K1 - p.B * x.K2) - BD * ((t2 * C1) * u + (t2 * tau * S3) * Wv);
    x.K2 += (tau * S1) * u + (t2 * C1) * Wv;
    x.K2 += ((x.K2sq0 - squared_norm(x.K2)) * x.half_inv_K2sq0) * x.K2;
    compensated_add(x.R, x.R_err, dR);
  }
  V3 force(const LieLanes& x) {
    ++evals;
    return batch::BODYPOINT_BATCH_NS::force(p, x.R);
  }
  void apply_kick(LieLanes& x, double tau, const V3& F) const { compensated_add(x.K1, x.K1_err, splat(tau) * F); }
  void kick(LieLanes& x, double tau) { apply_kick(x, tau, force(x)); }
  Physical to_physical(const LieLanes& x) const {
    const V3 K1 = x.K1 - x.K1_err;
    return {x.R - x.R_err, (p.J * K1 - p.B * x.K2) * p.inv_D, (p.m * x.K2 - p.B * K1) * p.inv_D};
  }
};

// --- the thesis's kernel (splitting::ThesisKernel<OriginCentre, true>, no code slip) --------------

struct ThesisLanes {
  Physical s;
  V3 gyro;
};

struct ThesisKernel {
  using state_type = ThesisLanes;
  static constexpr bool mergeable = false;
  Params p;
  long evals = 0;

  ThesisLanes initial_state(const Physical& s) const { return {s, V3{splat(0.0), splat(0.0), splat(0.0)}}; }
  void begin_step(ThesisLanes& x) const { x.gyro = cross(x.s.w, x.s.v); }
  void drift(ThesisLanes& x, double tau) const { x.s.R += splat(tau) * x.s.v; }
  void kick(ThesisLanes& x, double tau) {
    ++evals;
    const V3 F = force(p, x.s.R);
    const Lane c = tau * p.inv_D;
    x.s.v += c * (p.J * F - (p.B * p.B) * x.gyro);
    x.s.w += c * ((-p.B) * F + (p.m * p.B) * x.gyro);
  }
  Physical to_physical(const ThesisLanes& x) const { return x.s; }
};

/// The final state and the monitor's statistics of each member (abi::kOut doubles each).
void report(const Physical& f, const Monitor& monitor, std::size_t count, double* out) {
  for (std::size_t i = 0; i < count; ++i) {
    double* o = out + i * abi::kOut;
    put(f.R, i, o);
    put(f.v, i, o + 3);
    put(f.w, i, o + 6);
    monitor.stats(i, o + 9);
  }
}

/// Runs `Seq` with kernel K on the lanes; returns the force evaluations, or abi::kStopped.
template <const auto& Seq, class K>
long run_splitting(K kernel, const Physical& s0, double h, long steps, std::size_t count, double* out,
                   Canceller cancel) {
  Monitor monitor(kernel.p, s0, h);
  Observer<K> obs{kernel, monitor, cancel};
  typename K::state_type x = kernel.initial_state(s0);
  sp::integrate<Seq>(kernel, x, h, steps, obs);
  if (obs.stopped) return abi::kStopped;
  report(kernel.to_physical(x), monitor, count, out);
  return kernel.evals;
}

// --- odeint's runge_kutta4 on EquationsOfMotion<OriginCentre, true> (detail/equations.hpp) -------

struct Ode {
  V3 R, v, w;
};

struct Rhs {
  Lane cJ, cBB, cB, cmB;
  Params p;
  Ode operator()(const Ode& x) const {
    const V3 F = force(p, x.R);
    const V3 wxv = cross(x.w, x.v);
    return {x.v, cJ * F - cBB * wxv, (-cB) * F + cmB * wxv};
  }
};

/// odeint's scale_sumN: 1.0 x + a1 k1 + a2 k2 + ..., left to right (zero coefficients included).
Ode stage(const Ode& x, int n, const double* a, const Ode* const* k) {
  Ode r{splat(1.0) * x.R, splat(1.0) * x.v, splat(1.0) * x.w};
  for (int j = 0; j < n; ++j) {
    r.R = r.R + splat(a[j]) * k[j]->R;
    r.v = r.v + splat(a[j]) * k[j]->v;
    r.w = r.w + splat(a[j]) * k[j]->w;
  }
  return r;
}

long run_rk4(const Params& p, const Physical& s0, double h, long steps, std::size_t count, double* out,
             Canceller cancel) {
  const Lane D = p.m * p.J - p.B * p.B;
  const Rhs f{p.J / D, p.B * p.B / D, p.B / D, p.m * p.B / D, p};
  Monitor monitor(p, s0, h);
  Ode x{s0.R, s0.v, s0.w};
  // odeint's runge_kutta4 tableau (a = 1/2; 0, 1/2; 0, 0, 1; b = 1/6, 1/3, 1/3, 1/6), each times h.
  const double a2[1] = {0.5 * h}, a3[2] = {0.0 * h, 0.5 * h}, a4[3] = {0.0 * h, 0.0 * h, 1.0 * h};
  const double b[4] = {(1.0 / 6.0) * h, (1.0 / 3.0) * h, (1.0 / 3.0) * h, (1.0 / 6.0) * h};
  for (long i = 0; i < steps; ++i) {
    const Ode k1 = f(x);
    const Ode* k[4] = {&k1, nullptr, nullptr, nullptr};
    const Ode k2 = f(stage(x, 1, a2, k));
    k[1] = &k2;
    const Ode k3 = f(stage(x, 2, a3, k));
    k[2] = &k3;
    const Ode k4 = f(stage(x, 3, a4, k));
    k[3] = &k4;
    x = stage(x, 4, b, k);
    monitor.step({x.R, x.v, x.w});
    if (!cancel(i + 1)) return abi::kStopped;
  }
  report({x.R, x.v, x.w}, monitor, count, out);
  return 4 * steps;
}

using Runner = long (*)(const Params&, const Physical&, double, long, std::size_t, double*, Canceller);
template <const auto& Seq>
long lie(const Params& p, const Physical& s0, double h, long steps, std::size_t count, double* out, Canceller cancel) {
  return run_splitting<Seq>(LieKernel{p}, s0, h, steps, count, out, cancel);
}
template <const auto& Seq>
long thesis(const Params& p, const Physical& s0, double h, long steps, std::size_t count, double* out,
            Canceller cancel) {
  return run_splitting<Seq>(ThesisKernel{p}, s0, h, steps, count, out, cancel);
}

/// Every batch runner, numbered as the catalogue numbers them (splitting/catalogue.hpp kBatchRk4,
/// batch_thesis_kernel, batch_lie_kernel): RK4, the thesis family's tables, the Lie-Poisson ones.
struct Runners {
  Runner run[sp::kBatchKernels];
};
template <class... T, class... L>
constexpr Runners all_runners(sp::List<T...> /*thesis*/, sp::List<L...> /*lie*/) {
  return {{&run_rk4, &thesis<sp::ops_of<typename sp::entry_t<T>::type>>...,
           &lie<sp::ops_of<typename sp::entry_t<L>::type>>...}};
}
constexpr Runners kRunners = all_runners(sp::ThesisTables{}, sp::LiePoissonTables{});
static_assert(sizeof(kRunners.run) / sizeof(Runner) == 1 + sp::size(sp::ThesisTables{}) + sp::size(sp::LiePoissonTables{}));

/// The batch runner numbered `kernel`, or nullptr.
Runner runner(int kernel) { return kernel >= 0 && kernel < sp::kBatchKernels ? kRunners.run[kernel] : nullptr; }

}  // namespace

std::size_t width() { return W; }

bool supports(int kernel) { return runner(kernel) != nullptr; }

long run(int kernel, const double* in, std::size_t count, double h, long steps, double* out, abi::Poll poll,
         const void* context) {
  const Runner r = runner(kernel);
  if (!r || count == 0 || count > W) return -1;
  Params p{lane_of(in, count, 0), lane_of(in, count, 1), lane_of(in, count, 2), lane_of(in, count, 3), {}};
  p.inv_D = 1.0 / (p.m * p.J - p.B * p.B);
  const Physical s0{v3_of(in, count, 4), v3_of(in, count, 7), v3_of(in, count, 10)};
  return r(p, s0, h, steps, count, out, Canceller{poll, context});
}

}  // namespace bodypoint::batch::BODYPOINT_BATCH_NS
