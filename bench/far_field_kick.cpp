// far_field_kick: where the far field's spin resonances come from, and what kicks that know the spin
// achieve against them (docs/measurements.md, "Limits, measured").
//
// A pass that stays far from the centre (the thesis scene, Kz = 0.1, d = 50, t = 80), integrated by the
// exact Lie-Poisson drift with three kinds of kick, in Strang's and Yoshida's 4th-order composition, at
// fixed steps h around the spin period 2 pi/Omega_so:
//   at R      the splitting's kick, K1 += tau F(R);
//   at G      a kick averaged over the helix the drift follows: the force at its axis, the guiding
//             centre G = R + K1 x K2/|K1|^2, with K2 += (G - R) x dK1 so that K2Q = R x K1 + K2 is kept;
//   filtered  the kick at R plus what the drift makes of a force spread over the step instead of one
//             impulse at its middle: with the force constant over a Strang step D(tau/2) K(tau) D(tau/2),
//             the exact flow's K2 responds to K1(t) = K1 + F t as (B/D) K2 x int_0^tau Rot(u) F (tau - u) du,
//             the step's impulse as (B/D) K2 x tau int_0^{tau/2} Rot(u) F du (Rot: the drift's turn of K2
//             about K1 at Omega_so); the kick adds the difference, turned back to the middle of the step,
//             and moves R by dK2 x K1/|K1|^2 so that K2Q is kept. It is exact to first order in F for a
//             constant force at any spin angle per step, and the Strang step again as Omega_so tau -> 0.
// Then the bound of every such kick: steps that solve a frozen force exactly (the flow of T - F.R, or
// of T with the force linearised about the step's middle, integrated in 0.05-rad sub-steps), alone and
// composed by Yoshida's weights.
// If the resonance at Omega_so h = 2 pi came from sampling the force at one phase of the helix, the
// kick at G would not have it; if it came from the impulse alone, the filtered kick and the frozen-force
// steps would not. Prints the relative error of the final position against the same composition with
// kicks at R at h = 0.002 (error ~1e-15 there).
#include "bodypoint/field.hpp"
#include "bodypoint/splitting/classic.hpp"
#include "bodypoint/splitting/composition.hpp"
#include "bodypoint/splitting/lie_poisson.hpp"
#include "bodypoint/splitting/yoshida.hpp"

#include <cmath>
#include <cstdio>
#include <span>

namespace {

using namespace bodypoint;
namespace sp = bodypoint::splitting;

const BodyPoint kBody{1.0, 0.7, 1.0};  // table 3.1
const OriginCentre kField{-2.0};
constexpr double kK1 = 5.0, kKx = 2.0, kKz = 0.1, kD = 50.0, kL = 200.0, kTEnd = 80.0;
/// The frozen-force steps' sub-steps turn the spin by at most this (Yoshida 4 errs ~1e-15 there).
constexpr double kSubStepAngle = 0.05;

/// The splitting's kernel with the kick taken at the guiding centre (file comment); the drift is its own.
struct GuidingCentreKick {
  using state_type = sp::LieState;
  static constexpr bool mergeable = false;  // the engine calls kick(), never force()/apply_kick()
  sp::LiePoissonKernel<OriginCentre, true> lp;

  GuidingCentreKick(const BodyPoint& p, const OriginCentre& f) : lp(p, f) {}
  void begin_step(sp::LieState&) const {}
  void drift(sp::LieState& x, double tau) const { lp.drift(x, tau); }
  void kick(sp::LieState& x, double tau) const {
    const Vec3 to_axis = x.K1.cross(x.K2) / x.K1.squaredNorm();  // G - R
    const Vec3 dK1 = tau * lp.field.force(x.R + to_axis);
    x.K1 += dK1;
    x.K2 += to_axis.cross(dK1);
  }
};

/// The splitting's kernel with the filtered kick (file comment). In a Strang-based composition a kick
/// of weight tau sits in the middle of a Strang sub-step of length tau, which the filter assumes.
struct FilteredKick {
  using state_type = sp::LieState;
  static constexpr bool mergeable = false;
  sp::LiePoissonKernel<OriginCentre, true> lp;

  FilteredKick(const BodyPoint& p, const OriginCentre& f) : lp(p, f) {}
  void begin_step(sp::LieState&) const {}
  void drift(sp::LieState& x, double tau) const { lp.drift(x, tau); }
  void kick(sp::LieState& x, double tau) const {
    const Vec3 F = lp.field.force(x.R);
    const double BD = lp.p.B / lp.p.D(), k = x.K1.norm();
    const Vec3 e = x.K1 / k;
    const Vec3 Fp = F - F.dot(e) * e, P = e.cross(Fp);
    // Exact minus impulse response of the step's end, per component of F across K1 (file comment),
    // at spin angle th = Omega_so tau: cosine part (1 - cos th)/th^2 - sin(th/2)/th, sine part
    // (th - sin th)/th^2 - (1 - cos(th/2))/th; their series below 1e-3 rad.
    const double th = BD * k * tau;
    double dc = -th * th / 48.0, ds = th / 24.0;
    if (std::abs(th) >= 1e-3) {
      dc = (1.0 - std::cos(th)) / (th * th) - std::sin(0.5 * th) / th;
      ds = (th - std::sin(th)) / (th * th) - (1.0 - std::cos(0.5 * th)) / th;
    }
    const Vec3 end = tau * tau * (dc * Fp - ds * P);
    const Vec3 middle = std::cos(0.5 * th) * end + std::sin(0.5 * th) * e.cross(end);  // the half drift undone
    const Vec3 dK2 = BD * x.K2.cross(middle);
    x.K2 += dK2;
    x.R += dK2.cross(x.K1) / (k * k);
    x.K1 += tau * F;
  }
};

/// A force frozen over one step: F0 + G (R - Rm), G = 0 for a constant force.
struct FrozenField {
  Vec3 F0 = Vec3::Zero(), Rm = Vec3::Zero();
  Eigen::Matrix3d G = Eigen::Matrix3d::Zero();
  [[nodiscard]] Vec3 force(const Vec3& R) const { return F0 + G * (R - Rm); }
};

constexpr auto kStrang = sp::flatten(sp::strang_dkd_table);
constexpr auto kYoshida4 = sp::flatten(sp::yoshida4);

sp::LieState start() {
  return sp::to_lie({Vec3(-kL, kD - kKz / kK1, 0.0), Vec3(kK1, 0.0, 0.0), Vec3(kKx, 0.0, -kKz)});
}

/// The final state after t = kTEnd in steps of about h (the library's composition engine).
template <const auto& Ops, class Kernel>
Momenta run(double h) {
  Kernel k(kBody, kField);
  sp::LieState x = start();
  const long n = std::lround(kTEnd / h);
  sp::NullObserver none;
  sp::integrate<Ops>(k, x, kTEnd / static_cast<double>(n), n, none);
  return sp::from_lie(x);
}

/// One step of length tau that solves the frozen force exactly (file comment): the force (and, when
/// `linear`, its gradient) at the middle of the free drift, then the flow of the frozen problem.
void frozen_step(sp::LieState& x, double tau, bool linear) {
  sp::LieState mid = x;
  sp::LiePoissonKernel<OriginCentre, true> free(kBody, kField);
  free.drift(mid, 0.5 * tau);
  FrozenField f;
  f.Rm = mid.R;
  f.F0 = kField.force(mid.R);
  if (linear) {
    const double r = mid.R.norm();
    f.G = (-kField.A / (r * r * r)) * (Eigen::Matrix3d::Identity() - 3.0 * mid.R * mid.R.transpose() / (r * r));
  }
  sp::LiePoissonKernel<FrozenField, true> k(kBody, f);
  const double spin_rate = std::abs(kBody.B) * x.K1.norm() / kBody.D();
  const long n = std::max(1L, std::lround(std::ceil(std::abs(tau) * spin_rate / kSubStepAngle)));
  sp::NullObserver none;
  sp::integrate<kYoshida4>(k, x, tau / static_cast<double>(n), n, none);
}

/// Frozen-force steps of about h composed with the weights g (Strang: {1}).
Momenta run_frozen(std::span<const double> g, double h, bool linear) {
  sp::LieState x = start();
  const long n = std::lround(kTEnd / h);
  const double step = kTEnd / static_cast<double>(n);
  for (long i = 0; i < n; ++i)
    for (double w : g) frozen_step(x, w * step, linear);
  return sp::from_lie(x);
}

using AtR = sp::LiePoissonKernel<OriginCentre, true>;

double error(const Momenta& m, const Momenta& ref) { return (m.R - ref.R).norm() / ref.R.norm(); }

template <const auto& Ops>
void print_kicks(double h, const Momenta& ref) {
  for (const Momenta& m : {run<Ops, AtR>(h), run<Ops, GuidingCentreKick>(h), run<Ops, FilteredKick>(h)})
    std::printf(" %.2e |", error(m, ref));
}

}  // namespace

int main() {
  const double spin_rate = std::abs(kBody.B) * kK1 / kBody.D();
  std::printf("far pass (Kz = %g, d = %g, t = %g): relative error of R(t) against the same composition at h = 0.002\n",
              kKz, kD, kTEnd);
  std::printf("| h | spin angle per step [rad] | Strang, kick at R | at G | filtered | Yoshida 4, at R | at G | filtered "
              "| frozen F, Strang | Yoshida 4 | linearised F, Strang | Yoshida 4 |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  const Momenta ref_strang = run<kStrang, AtR>(0.002), ref_yoshida = run<kYoshida4, AtR>(0.002);
  const double strang_weights[] = {1.0};
  for (double h : {0.1, 0.3, 0.4, 0.45, 0.5, 0.7, 0.8, 0.9, 0.916, 0.95, 1.0, 1.2, 1.6, 1.83, 2.0, 3.0}) {
    std::printf("| %g | %.2f |", h, spin_rate * h);
    print_kicks<kStrang>(h, ref_strang);
    print_kicks<kYoshida4>(h, ref_yoshida);
    for (bool linear : {false, true})
      std::printf(" %.2e | %.2e |", error(run_frozen(strang_weights, h, linear), ref_yoshida),
                  error(run_frozen(sp::yoshida4_weights, h, linear), ref_yoshida));
    std::printf("\n");
  }
}
