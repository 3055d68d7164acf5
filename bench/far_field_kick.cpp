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
#include "bodypoint/splitting/lie_poisson.hpp"

#include <cmath>
#include <cstdio>

namespace {

using namespace bodypoint;
namespace sp = bodypoint::splitting;

const BodyPoint kBody{1.0, 0.7, 1.0};  // table 3.1
const OriginCentre kField{-2.0};
constexpr double kK1 = 5.0, kKx = 2.0, kKz = 0.1, kD = 50.0, kL = 200.0, kTEnd = 80.0;

enum class Kick { at_R, at_G };
enum class Composition { strang, yoshida4 };

Momenta run(double h, Kick where, Composition comp) {
  sp::LiePoissonKernel<OriginCentre, true> k(kBody, kField);
  sp::LieState x = sp::to_lie({Vec3(-kL, kD - kKz / kK1, 0.0), Vec3(kK1, 0.0, 0.0), Vec3(kKx, 0.0, -kKz)});
  const auto kick = [&](double tau) {
    if (where == Kick::at_R) {
      k.kick(x, tau);
      return;
    }
    const Vec3 to_axis = x.K1.cross(x.K2) / x.K1.squaredNorm();  // G - R
    const Vec3 dK1 = tau * kField.force(x.R + to_axis);
    x.K1 += dK1;
    x.K2 += to_axis.cross(dK1);
  };
  const long n = std::lround(kTEnd / h);
  const double s = kTEnd / static_cast<double>(n);
  // Yoshida's triple jump (H. Yoshida, Phys. Lett. A 150 (1990) 262): w1 = 1/(2 - 2^(1/3)), w0 = 1 - 2 w1.
  const double w1 = 1.0 / (2.0 - std::cbrt(2.0)), w0 = 1.0 - 2.0 * w1;
  for (long i = 0; i < n; ++i) {
    if (comp == Composition::strang) {
      k.drift(x, 0.5 * s);
      kick(s);
      k.drift(x, 0.5 * s);
    } else {
      k.drift(x, 0.5 * w1 * s);
      kick(w1 * s);
      k.drift(x, 0.5 * (w1 + w0) * s);
      kick(w0 * s);
      k.drift(x, 0.5 * (w1 + w0) * s);
      kick(w1 * s);
      k.drift(x, 0.5 * w1 * s);
    }
  }
  return sp::from_lie(x);
}

}  // namespace

int main() {
  const double spin_rate = std::abs(kBody.B) * kK1 / kBody.D();
  std::printf("far pass (Kz = %g, d = %g, t = %g): relative error of R(t) against the same composition at h = 0.002\n",
              kKz, kD, kTEnd);
  std::printf("| h | spin angle per step [rad] | Strang, kick at R | Strang, kick at G | Yoshida 4, at R | Yoshida 4, at G |\n");
  std::printf("|---|---|---|---|---|---|\n");
  const Momenta ref[2] = {run(0.002, Kick::at_R, Composition::strang), run(0.002, Kick::at_R, Composition::yoshida4)};
  for (double h : {0.1, 0.3, 0.4, 0.45, 0.5, 0.7, 0.8, 0.9, 0.916, 0.95, 1.0, 1.2, 1.6, 1.83, 2.0, 3.0}) {
    std::printf("| %g | %.2f |", h, spin_rate * h);
    for (int c = 0; c < 2; ++c)
      for (Kick where : {Kick::at_R, Kick::at_G}) {
        const Momenta m = run(h, where, c == 0 ? Composition::strang : Composition::yoshida4);
        std::printf(" %.2e |", (m.R - ref[c].R).norm() / ref[c].R.norm());
      }
    std::printf("\n");
  }
}
