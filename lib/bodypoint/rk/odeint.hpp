// bodypoint: the thesis's Runge-Kutta and Adams-Bashforth methods, from Boost.Odeint.
//
// Thesis sec. 2.1 (classical RK4) and 2.2 (Adams-Bashforth 4, eq. 2.1, started with RK4) on the
// corrected equations of motion (rhs.hpp). Odeint's `adams_bashforth<4>` is given `runge_kutta4`
// as its initialising stepper, as in the thesis.
#pragma once

#include "bodypoint/rhs.hpp"

#include <boost/numeric/odeint/stepper/adams_bashforth.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta4.hpp>

namespace bodypoint::rk {

namespace odeint = boost::numeric::odeint;

using Rk4 = odeint::runge_kutta4<OdeState<double>>;

using Ab4 = odeint::adams_bashforth<4, OdeState<double>, double, OdeState<double>, double,
                                    odeint::range_algebra, odeint::default_operations,
                                    odeint::initially_resizer, Rk4>;

}  // namespace bodypoint::rk
