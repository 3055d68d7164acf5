// bodypoint: the production system of the equations of motion over a force field (field.hpp), which
// the Boost.Odeint and GSL drivers and the batch's RK4 run (rhs.hpp has the equations and the state
// layout). Internal (not installed).
#pragma once

#include "bodypoint/field.hpp"
#include "bodypoint/model.hpp"
#include "bodypoint/rhs.hpp"

namespace bodypoint {

/// The system for a given field; `Spin = false` (B = 0) skips the gyroscopic terms entirely,
/// leaving dw/dt = 0. Counts its own calls (one call = one force evaluation). The coefficients
/// J/D, B^2/D, B/D and m B/D are computed once: odeint may call this out of line, and a division per
/// call made an RK4 step 1.8x slower (bench_steps).
template <class Field, bool Spin>
struct EquationsOfMotion {
  BodyPoint p;
  Field field;
  long* evals = nullptr;  ///< optional counter of calls

  EquationsOfMotion(const BodyPoint& bp, Field f, long* counter = nullptr)
      : p(bp), field(std::move(f)), evals(counter), cJ_(bp.J / bp.D()), cBB_(bp.B * bp.B / bp.D()),
        cB_(bp.B / bp.D()), cmB_(bp.m * bp.B / bp.D()), inv_m_(1.0 / bp.m) {}

  void operator()(const OdeState<double>& x, OdeState<double>& dxdt, double /*t*/) const {
    eval(x.data(), dxdt.data());
  }

  /// The same on plain arrays of nine (GSL's right-hand side calls this on its own arrays: copying
  /// them into OdeState and back made GSL's runs 1.26x slower than a plain C right-hand side).
  void eval(const double* x, double* dxdt) const {
    if (evals) ++*evals;
    const Vec3 R(x[0], x[1], x[2]);
    const Vec3 F = field.force(R);
    double dv[3], dw[3];
    if constexpr (Spin) {
      const double wxv[3] = {x[7] * x[5] - x[8] * x[4], x[8] * x[3] - x[6] * x[5], x[6] * x[4] - x[7] * x[3]};
      for (int i = 0; i < 3; ++i) {
        dv[i] = cJ_ * F[i] - cBB_ * wxv[i];
        dw[i] = -cB_ * F[i] + cmB_ * wxv[i];
      }
    } else {
      for (int i = 0; i < 3; ++i) {
        dv[i] = inv_m_ * F[i];
        dw[i] = 0.0;
      }
    }
    for (int i = 0; i < 3; ++i) {
      dxdt[i] = x[3 + i];
      dxdt[3 + i] = dv[i];
      dxdt[6 + i] = dw[i];
    }
  }

 private:
  double cJ_, cBB_, cB_, cmB_, inv_m_;
};

}  // namespace bodypoint
