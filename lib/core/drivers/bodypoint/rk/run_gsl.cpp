// bodypoint: GSL's step-size-controlled Runge-Kutta steppers as peers (gsl-rk8pd, gsl-rkf45).
//
// The GNU Scientific Library's gsl_odeiv2 evolve/control/step framework (GSL reference manual,
// "Ordinary Differential Equations"): rk8pd is Prince-Dormand 8(7), rkf45 Runge-Kutta-Fehlberg 4(5);
// the standard control keeps the local error below tol (1 + |y|) per component (eps_abs = eps_rel =
// tol). The right-hand side is the one Boost.Odeint integrates (rhs.hpp), so every peer solves the same
// system. gsl_odeiv2_evolve_apply limits the last step to the end time, so t_end is hit exactly.
#include "bodypoint/rk/run_gsl.hpp"

#include "bodypoint/detail/equations.hpp"
#include "bodypoint/detail/run_support.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>

namespace bodypoint {
namespace {

using detail::dispatch;
using detail::observe;


template <class System>
int gsl_rhs(double /*t*/, const double y[], double f[], void* params) {
  static_cast<const System*>(params)->eval(y, f);  // on GSL's arrays, as a plain C function would
  return GSL_SUCCESS;
}

struct GslDeleter {
  void operator()(gsl_odeiv2_step* s) const { gsl_odeiv2_step_free(s); }
  void operator()(gsl_odeiv2_control* c) const { gsl_odeiv2_control_free(c); }
  void operator()(gsl_odeiv2_evolve* e) const { gsl_odeiv2_evolve_free(e); }
};

/// How the controlled-step driver words GSL's failures ("gsl: ...").
struct Gsl {
  static constexpr const char* name = "gsl";
};
using GslSays = detail::LibrarySays<Gsl>;

RunResult run_gsl(const gsl_odeiv2_step_type* type, const Body& body, const std::vector<Centre>& centres,
                  const Advance& how, const RunOptions& options) {
  const auto& spec = std::get<ControlledSteps>(how);
  gsl_set_error_handler_off();
  return dispatch(body, centres, [&](const auto& field, auto spin) {
    using Field = std::decay_t<decltype(field)>;
    using System = EquationsOfMotion<Field, decltype(spin)::value>;
    long evals = 0;
    const System sys{body.p, field, &evals};
    gsl_odeiv2_system gsys{&gsl_rhs<System>, nullptr, 9, const_cast<System*>(&sys)};
    std::unique_ptr<gsl_odeiv2_step, GslDeleter> step(gsl_odeiv2_step_alloc(type, 9));
    std::unique_ptr<gsl_odeiv2_control, GslDeleter> control(gsl_odeiv2_control_y_new(spec.tol, spec.tol));
    std::unique_ptr<gsl_odeiv2_evolve, GslDeleter> evolve(gsl_odeiv2_evolve_alloc(9));
    if (!step || !control || !evolve) throw Error("gsl: out of memory");
    const double t_end = spec.t_end;
    detail::StepStats st;
    auto to_physical = [](const OdeState<double>& x) { return from_ode(x); };
    RunResult r = observe(body.p, field, body.s0, options, detail::grid_of(spec), to_physical, [&](auto& obs) {
      auto try_step = [&](OdeState<double>& x, double& t, double& dt) {  // evolve retries and lands on t_end
        const int status =
            gsl_odeiv2_evolve_apply(evolve.get(), control.get(), step.get(), &gsys, &t, t_end, &dt, x.data());
        if (status != GSL_SUCCESS)
          throw Error("gsl: step failed at t = " + std::to_string(t) + " (" + gsl_strerror(status) + ")");
        return true;
      };
      return from_ode(detail::controlled_loop<GslSays>(to_ode(body.s0), spec.h0, t_end, st, obs, try_step));
    });
    r.force_evals = evals;
    st.record(r, t_end);
    return r;
  });
}

}  // namespace

RunResult run_gsl_rk8pd(const Body& b, const std::vector<Centre>& c, const Advance& s, const RunOptions& k) {
  return run_gsl(gsl_odeiv2_step_rk8pd, b, c, s, k);
}
RunResult run_gsl_rkf45(const Body& b, const std::vector<Centre>& c, const Advance& s, const RunOptions& k) {
  return run_gsl(gsl_odeiv2_step_rkf45, b, c, s, k);
}

}  // namespace bodypoint
