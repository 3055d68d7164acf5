// bodypoint: the thesis's Runge-Kutta and Adams-Bashforth methods, from Boost.Odeint.
//
// Thesis sec. 2.1 (classical RK4) and 2.2 (Adams-Bashforth 4, eq. 2.1, started with RK4) on the
// corrected equations of motion (rhs.hpp). Odeint's `adams_bashforth<4>` is given `runge_kutta4`
// as its initialising stepper, as in the thesis.
#pragma once

#include "bodypoint/rhs.hpp"

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
