// bodypoint: time-transformed splittings that shrink the physical step near a Coulomb centre while
// keeping a fixed fictitious step ds, explicit and time-symmetric.
//
// Both kernels act on the Lie-Poisson state (R, K1, K2) extended by the physical time t and run on
// the generic composition engine with any coefficient table (splitting/composition.hpp), so every
// table keeps its order in ds. The physical time is accumulated with compensated summation.
//
// LogHKernel - logarithmic Hamiltonian (M. Mikkola, S. Tanikawa, "Explicit symplectic algorithms for
//   time-transformed Hamiltonians", Celest. Mech. Dyn. Astron. 74 (1999) 287; M. Preto, S. Tremaine,
//   "A class of symplectic integrators with adaptive time step for separable Hamiltonian systems",
//   Astron. J. 118 (1999) 2532). In extended phase space with p_t = -E,
//     H~ = ln(Pi(R)) - ln(-(T + p_t))                                 (docs/physics.md)
//   is separable; its flows are
//     drift for ds: dt = ds/(E - T) (T is constant along the exact kinetic drift), then the exact
//                   kinetic drift for dt;
//     kick for ds:  K1 += ds F(R)/Pi(R).
//   On the energy shell dt/ds = 1/Pi ~ |R|/|A|. Needs Pi > 0 everywhere: every centre repulsive.
//   For a material point in one centre's field each leapfrog follows the exact Kepler orbit
//   (Mikkola-Tanikawa 1999, sec. 3): only the time along it carries error.
//   Numerics: g = E - T is carried as a state variable instead of being formed from E and T, which
//   would cancel catastrophically far from the centre (E ~ T ~ 12.5 while Pi ~ 0.01 on table 3.1, a
//   relative error eps E/Pi in every far-field dt). g is constant in drifts (T is) and changes in a
//   kick K1 -> K1 + delta by exactly -dT = -(J K1.delta + J |delta|^2/2 - B K2.delta)/D, which is
//   small when the force is; it starts at Pi(R0), its on-shell value.
//
// TtlKernel - time-transformed leapfrog (S. Mikkola, S. J. Aarseth, "A time-transformed leapfrog
//   scheme", Celest. Mech. Dyn. Astron. 84 (2002) 343), for any sign of A. With the time-step
//   function Omega(R) = sum |A_i|/|R - c_i| and an auxiliary W (W = Omega at the start), integrate in
//   s the system dR/ds = v/W, dt/ds = 1/W, dK2/ds = (B/D)(K2 x K1)/W, dK1/ds = F/Omega,
//   dW/ds = gradOmega.v/Omega, split into two exactly solvable parts:
//     drift for ds: dt = ds/W, exact kinetic drift for dt (K1, W constant);
//     kick for ds:  dt' = ds/Omega(R), K1 += dt' F, W += dt' gradOmega.(v_before + v_after)/2
//                   (v is linear in K1, so the average is the exact integral; R, K2 constant).
//   Along the exact flow of the sum W = Omega stays true, so the solution is the physical motion
//   reparametrised by dt/ds = 1/Omega, and any splitting table applies with its classical order.
#pragma once

#include "bodypoint/field.hpp"
#include "bodypoint/model.hpp"
#include "bodypoint/splitting/lie_poisson.hpp"

#include <cmath>
#include <string>
#include <type_traits>

namespace bodypoint::adaptive {

/// Lie-Poisson state plus the physical time (compensated) and the TTL's auxiliary W.
struct TimeState {
  splitting::LieState q;
  double t = 0.0;
  double t_err = 0.0;
  double W = 0.0;  ///< TTL: the auxiliary variable tracking Omega
  double g = 0.0;  ///< logH: E - T, carried (see above)
  [[nodiscard]] double time() const { return t - t_err; }
};

inline void advance_time(TimeState& x, double dt) { splitting::compensated_add(x.t, x.t_err, dt); }

template <class Field, bool Spin>
struct LogHKernel {
  using state_type = TimeState;
  static constexpr bool mergeable = true;

  splitting::LiePoissonKernel<Field, Spin> lp;  ///< the physical-time exact drift and kick
  double c = 0.0;  ///< constant added to Pi and to E - T: the physical step is at most ds/c

  LogHKernel(const BodyPoint& p, const Field& f, double c_ = 0.0)
      : lp(p, f), c(c_), inv_d_(1.0 / p.D()) {}

  [[nodiscard]] TimeState initial_state(const State& s0) const {
    TimeState x;
    x.q = lp.initial_state(s0);
    x.g = lp.field.potential(s0.R);  // E - T(0) = Pi(R0)
    return x;
  }
  /// The carried variable (RunOptions::carried): g, from which a run goes on on its energy shell.
  static double carried(const TimeState& x) { return x.g; }
  static void resume(TimeState& x, double carried) { x.g = carried; }
  void begin_step(TimeState&) const {}

  void drift(TimeState& x, double ds) const {
    const double gc = x.g + c;
    if (!(gc > 0.0))
      throw Error("logh: E - T + c = " + std::to_string(gc) + " <= 0 at t = " + std::to_string(x.time()) +
                  " (the fictitious step is too large for this encounter; reduce the fictitious step ds)");
    const double dt = ds / gc;
    lp.drift(x.q, dt);
    advance_time(x, dt);
  }

  void kick(TimeState& x, double ds) {
    ++lp.evals;
    Vec3 delta;  // the kick's change of K1, ds F/(Pi + c)
    if constexpr (std::is_same_v<Field, OriginCentre>) {
      // One centre: ds F/(Pi + c) = ds (-A) R / (r^2 (c r - A)), one division where F, Pi and their
      // quotient take two (the kick is on the step's critical path, see drift_functions).
      const double A = lp.field.A;
      const double r2 = x.q.R.squaredNorm();
      const double r = std::sqrt(r2);
      delta = (-A * ds / (r2 * (c * r - A))) * x.q.R;
    } else {
      Vec3 F;
      double P;
      lp.field.force_potential(x.q.R, F, P);
      delta = (ds / (P + c)) * F;
    }
    const BodyPoint& p = lp.p;
    x.g -= (p.J * (x.q.K1.dot(delta) + 0.5 * delta.squaredNorm()) - p.B * x.q.K2.dot(delta)) * inv_d_;
    splitting::compensated_add(x.q.K1, x.q.K1_err, delta);
  }

  [[nodiscard]] State to_physical(const TimeState& x) const { return lp.to_physical(x.q); }

 private:
  double inv_d_;  ///< 1/D: the kick's change of T without a division per stage
};

template <class Field, bool Spin>
struct TtlKernel {
  using state_type = TimeState;
  static constexpr bool mergeable = true;

  splitting::LiePoissonKernel<Field, Spin> lp;
  double c = 0.0;  ///< constant added to Omega: the physical step is at most ds/c

  TtlKernel(const BodyPoint& p, const Field& f, double c_ = 0.0)
      : lp(p, f), c(c_), inv_d_(1.0 / p.D()) {}

  [[nodiscard]] TimeState initial_state(const State& s0) const {
    TimeState x;
    x.q = lp.initial_state(s0);
    Vec3 F, grad;
    lp.field.force_omega(s0.R, F, x.W, grad);
    x.W += c;
    return x;
  }
  /// The carried variable (RunOptions::carried): W, which tracks Omega + c along the numerical solution.
  static double carried(const TimeState& x) { return x.W; }
  static void resume(TimeState& x, double carried) { x.W = carried; }
  void begin_step(TimeState&) const {}

  void drift(TimeState& x, double ds) const {
    const double dt = ds / x.W;
    lp.drift(x.q, dt);
    advance_time(x, dt);
  }

  void kick(TimeState& x, double ds) {
    ++lp.evals;
    Vec3 F, grad;
    double Omega;
    lp.field.force_omega(x.q.R, F, Omega, grad);
    const double dtp = ds / (Omega + c);
    // The mean of v = (J K1 - B K2)/D before and after the kick: v at K1 + dtp F / 2 (v is linear in K1).
    const Vec3 v_mean = (lp.p.J * (x.q.K1 + (0.5 * dtp) * F) - lp.p.B * x.q.K2) * inv_d_;
    lp.apply_kick(x.q, dtp, F);
    x.W += dtp * grad.dot(v_mean);
  }

  [[nodiscard]] State to_physical(const TimeState& x) const { return lp.to_physical(x.q); }

 private:
  double inv_d_;  ///< 1/D: velocities without a division per component
};

}  // namespace bodypoint::adaptive
