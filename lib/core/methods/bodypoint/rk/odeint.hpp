// bodypoint: the thesis's Runge-Kutta and Adams-Bashforth methods, from Boost.Odeint.
//
// Thesis sec. 2.1 (classical RK4) and 2.2 (Adams-Bashforth 4, eq. 2.1, started with RK4) on the
// corrected equations of motion (rhs.hpp). Odeint's `adams_bashforth<4>` is given `runge_kutta4`
// as its initialising stepper, as in the thesis.
#pragma once

#include "bodypoint/rhs.hpp"

#include <array>
#include <cstddef>
#include <type_traits>

#include <boost/numeric/odeint/stepper/adams_bashforth.hpp>
#include <boost/numeric/odeint/stepper/bulirsch_stoer.hpp>
#include <boost/numeric/odeint/stepper/controlled_runge_kutta.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta4.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_dopri5.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_fehlberg78.hpp>

namespace bodypoint::rk {

namespace odeint = boost::numeric::odeint;

using Rk4 = odeint::runge_kutta4<OdeState<double>>;

using Ab4 = odeint::adams_bashforth<4, OdeState<double>, double, OdeState<double>, double,
                                    odeint::range_algebra, odeint::default_operations,
                                    odeint::initially_resizer, Rk4>;

/// The thesis's Adams-Bashforth 4 as its Java code runs it (AdamsBashfortForSystem): the formula and
/// the RK4 start of Ab4, but it keeps the three past states and evaluates the right-hand side at them
/// and at the current state every step, 4 force evaluations per step where odeint's keeps the
/// derivatives and evaluates one (thesis table 4.1 counts 4). Its states are Ab4's; only its cost
/// differs: the thesis's timing claims about AB4 are measured with it (ab4-thesis).
class ThesisAb4 {
 public:
  template <class System>
  void do_step(System sys, OdeState<double>& x, double t, double dt) {
    if (filled_ < 3) {  // RK4 start-up, keeping the states the formula needs
      past_[filled_++] = x;
      start_.do_step(sys, x, t, dt);
      return;
    }
    OdeState<double> f0, f1, f2, f3;  // at x_n, x_{n-1}, x_{n-2}, x_{n-3}: all evaluated again
    sys(x, f0, t);
    sys(past_[2], f1, t - dt);
    sys(past_[1], f2, t - 2.0 * dt);
    sys(past_[0], f3, t - 3.0 * dt);
    past_[0] = past_[1];
    past_[1] = past_[2];
    past_[2] = x;
    for (std::size_t i = 0; i < x.size(); ++i)  // thesis eq. 2.1
      x[i] += dt * (55.0 * f0[i] - 59.0 * f1[i] + 37.0 * f2[i] - 9.0 * f3[i]) / 24.0;
  }

 private:
  Rk4 start_;
  std::array<OdeState<double>, 3> past_{};
  int filled_ = 0;
};

/// Step-size-controlled references and competitors (Dormand-Prince 5(4), Fehlberg 7(8),
/// Bulirsch-Stoer), each with odeint's standard error checker at abs = rel = tol.
using Dopri5 = odeint::controlled_runge_kutta<odeint::runge_kutta_dopri5<OdeState<double>>>;
using Rkf78 = odeint::controlled_runge_kutta<odeint::runge_kutta_fehlberg78<OdeState<double>>>;
using BulirschStoer = odeint::bulirsch_stoer<OdeState<double>>;

#pragma GCC diagnostic push
// GCC 12 reports the default-constructed stepper that odeint's controller copies as (maybe-)
// uninitialised: a false positive inside Boost (its members are work arrays written before use).
#ifndef __clang__  // a GCC-only warning group
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#pragma GCC diagnostic ignored "-Wuninitialized"
template <class Controlled>
Controlled make_controlled(double tol) {
  if constexpr (std::is_same_v<Controlled, BulirschStoer>) {
    return BulirschStoer(tol, tol);
  } else {
    using Checker = typename Controlled::error_checker_type;
    return Controlled(Checker(tol, tol));
  }
}
#pragma GCC diagnostic pop

}  // namespace bodypoint::rk
