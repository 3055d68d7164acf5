// bodypoint: the thesis's drift/kick kernel with the gyroscopic term frozen at the step start.
//
// Thesis eq. 2.2 and 2.12 (sec. 2.3, 2.5), with the corrected equations of motion
// (docs/physics.md, Erratum 1):
//   drift:  R += c h v
//   kick:   v += d h (J F(R) - B^2 g)/D,   w += d h (-B F(R) + m B g)/D,   g = w_{i-1} x v_{i-1}
// where g is evaluated once at the start of each step and held fixed through its stages.
// For B != 0 this is not an exact splitting of any Hamiltonian: the frozen term makes every
// scheme of this family first-order accurate in the gyroscopic coupling and not symplectic
// (docs/physics.md "The thesis's integrators"). It is kept, faithfully, as the thesis's baseline.
#pragma once

#include "bodypoint/model.hpp"
#include "bodypoint/splitting/code_slip.hpp"

namespace bodypoint::splitting {


struct ThesisState {
  State s;
  Vec3 gyro = Vec3::Zero();  ///< w x v frozen at the start of the step
  int kick = 0;              ///< kicks taken in this step (for the code's slip only)
  double first_Fz = 0.0;     ///< z-component of the first kick's force (for the code's slip only)
};

template <class Field, bool Spin>
struct ThesisKernel {
  using state_type = ThesisState;
  /// A step depends on the state at its start (the frozen term): steps cannot share sub-flows.
  static constexpr bool mergeable = false;

  BodyPoint p;
  Field field;
  long evals = 0;

  ThesisKernel(const BodyPoint& bp, Field f) : p(bp), field(std::move(f)), inv_D_(1.0 / bp.D()) {}

  [[nodiscard]] ThesisState initial_state(const State& s0) const { return {s0, Vec3::Zero()}; }

  /// CodeSlip::none unless the scene reproduces the published code (set by the core layer's run loop, run.cpp).
  CodeSlip slip = CodeSlip::none;

  void begin_step(ThesisState& x) const {
    if constexpr (Spin) x.gyro = x.s.w.cross(x.s.v);
    x.kick = 0;
  }

  void drift(ThesisState& x, double tau) const { x.s.R += tau * x.s.v; }

  void kick(ThesisState& x, double tau) {
    ++evals;
    Vec3 F = field.force(x.s.R);
    Vec3 Fw = F;  // the force the spin kick sees (differs from F only under the code's slip)
    if (slip != CodeSlip::none) {
      if (++x.kick == 1) x.first_Fz = F.z();
      if (x.kick == 3) {
        F.z() = x.first_Fz;
        if (slip == CodeSlip::third_vw_z) Fw.z() = x.first_Fz;
      }
    }
    if constexpr (Spin) {
      const double c = tau * inv_D_;
      x.s.v += c * (p.J * F - p.B * p.B * x.gyro);
      x.s.w += c * (-p.B * Fw + p.m * p.B * x.gyro);
    } else {
      x.s.v += (tau / p.m) * F;
    }
  }

  [[nodiscard]] State to_physical(const ThesisState& x) const { return x.s; }

 private:
  double inv_D_;
};

}  // namespace bodypoint::splitting
