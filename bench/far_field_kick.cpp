// far_field_kick: where the far field's spin resonances come from (docs/developers.md, "Limits, measured").
//
// A pass that stays far from the centre (the thesis scene, Kz = 0.1, d = 50, t = 80), integrated by the
// exact Lie-Poisson drift with two kicks, in Strang's and Yoshida's 4th-order composition, at fixed steps
// h around the spin period 2 pi/Omega_so:
//   at R  the splitting's kick, K1 += tau F(R);
//   at G  a kick averaged over the helix the drift follows: the force at its axis, the guiding centre
//         G = R + K1 x K2/|K1|^2, with K2 += (G - R) x dK1 so that K2Q = R x K1 + K2 is kept.
// If the resonance at Omega_so h = 2 pi came from sampling the force at one phase of the helix, the
// kick at G would not have it. Prints the relative error of the final position against the same
// composition with kicks at R at h = 0.002 (error ~1e-15 there).
#include "bodypoint/field.hpp"
#include "bodypoint/splitting/classic.hpp"
#include "bodypoint/splitting/composition.hpp"
#include "bodypoint/splitting/lie_poisson.hpp"
#include "bodypoint/splitting/yoshida.hpp"

#include <cmath>
#include <cstdio>

namespace {

using namespace bodypoint;
namespace sp = bodypoint::splitting;

const BodyPoint kBody{1.0, 0.7, 1.0};  // table 3.1
const OriginCentre kField{-2.0};
constexpr double kK1 = 5.0, kKx = 2.0, kKz = 0.1, kD = 50.0, kL = 200.0, kTEnd = 80.0;

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

constexpr auto kStrang = sp::flatten(sp::strang_dkd_table);
constexpr auto kYoshida4 = sp::flatten(sp::yoshida4);

/// The final state after t = kTEnd in steps of about h (the library's composition engine).
template <const auto& Ops, class Kernel>
Momenta run(double h) {
  Kernel k(kBody, kField);
  sp::LieState x = sp::to_lie({Vec3(-kL, kD - kKz / kK1, 0.0), Vec3(kK1, 0.0, 0.0), Vec3(kKx, 0.0, -kKz)});
  const long n = std::lround(kTEnd / h);
  sp::NullObserver none;
  sp::integrate<Ops>(k, x, kTEnd / static_cast<double>(n), n, none);
  return sp::from_lie(x);
}

using AtR = sp::LiePoissonKernel<OriginCentre, true>;

template <const auto& Ops>
void print_pair(double h, const Momenta& ref) {
  for (const Momenta& m : {run<Ops, AtR>(h), run<Ops, GuidingCentreKick>(h)})
    std::printf(" %.2e |", (m.R - ref.R).norm() / ref.R.norm());
}

}  // namespace

int main() {
  const double spin_rate = std::abs(kBody.B) * kK1 / kBody.D();
  std::printf("far pass (Kz = %g, d = %g, t = %g): relative error of R(t) against the same composition at h = 0.002\n",
              kKz, kD, kTEnd);
  std::printf("| h | spin angle per step [rad] | Strang, kick at R | Strang, kick at G | Yoshida 4, at R | Yoshida 4, at G |\n");
  std::printf("|---|---|---|---|---|---|\n");
  const Momenta ref_strang = run<kStrang, AtR>(0.002), ref_yoshida = run<kYoshida4, AtR>(0.002);
  for (double h : {0.1, 0.3, 0.4, 0.45, 0.5, 0.7, 0.8, 0.9, 0.916, 0.95, 1.0, 1.2, 1.6, 1.83, 2.0, 3.0}) {
    std::printf("| %g | %.2f |", h, spin_rate * h);
    print_pair<kStrang>(h, ref_strang);
    print_pair<kYoshida4>(h, ref_yoshida);
    std::printf("\n");
  }
}
