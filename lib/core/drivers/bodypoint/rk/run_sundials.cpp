// bodypoint: SUNDIALS CVODE's variable-order Adams-Moulton method as a peer (cvode-adams).
//
// Driven as CVODE's guide drives a non-stiff problem (Hindmarsh et al. 2005; CVODE user guide, "Usage of
// CVODE"): CVodeCreate(CV_ADAMS) with the fixed-point nonlinear solver (no Jacobian), scalar tolerances
// rtol = atol = tol (its local error test is a weighted RMS norm of the components), CVodeSetStopTime so
// that the last step lands on t_end, and CVode(..., CV_ONE_STEP) step by step so that every step is observed.
// The right-hand side is the one Boost.Odeint and GSL integrate (equations.hpp), so every peer solves the same
// system; a force evaluation is one call of it (CVODE's fixed-point iterations call it once each).
#include "bodypoint/rk/run_sundials.hpp"

#include "bodypoint/detail/equations.hpp"
#include "bodypoint/detail/run_support.hpp"

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <string>
#include <type_traits>

namespace bodypoint {
namespace {

using detail::dispatch;
using detail::observe;

template <class System>
int cvode_rhs(sunrealtype /*t*/, N_Vector y, N_Vector ydot, void* user) {
  static_cast<const System*>(user)->eval(N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
  return 0;
}

struct Sundials {  // owns the context, the vector, the solver and CVODE's memory
  SUNContext ctx = nullptr;
  N_Vector y = nullptr;
  SUNNonlinearSolver nls = nullptr;
  void* mem = nullptr;
  Sundials() {
    if (SUNContext_Create(nullptr, &ctx) != 0) throw Error("cvode: cannot create its context");
  }
  Sundials(const Sundials&) = delete;
  Sundials& operator=(const Sundials&) = delete;
  ~Sundials() {
    if (mem) CVodeFree(&mem);
    if (nls) SUNNonlinSolFree(nls);
    if (y) N_VDestroy(y);
    if (ctx) SUNContext_Free(&ctx);
  }
};

/// How the controlled-step driver words CVODE's failures ("cvode: ...").
struct Cvode {
  static constexpr const char* name = "cvode";
};
using CvodeSays = detail::LibrarySays<Cvode>;

void check(int flag, const char* what) {
  if (flag < 0) throw Error(std::string("cvode: ") + what + " failed (flag " + std::to_string(flag) + ")");
}

}  // namespace

RunResult run_cvode_adams(const Body& body, const std::vector<Centre>& centres, const Advance& how,
                          const RunOptions& options) {
  const auto& spec = std::get<ControlledSteps>(how);
  return dispatch(body, centres, [&](const auto& field, auto spin) {
    using Field = std::decay_t<decltype(field)>;
    using System = EquationsOfMotion<Field, decltype(spin)::value>;
    long evals = 0;
    const System sys{body.p, field, &evals};
    Sundials s;
    const OdeState<double> x0 = to_ode(body.s0);
    s.y = N_VNew_Serial(static_cast<sunindextype>(x0.size()), s.ctx);
    if (!s.y) throw Error("cvode: out of memory");
    std::copy(x0.begin(), x0.end(), N_VGetArrayPointer(s.y));
    s.mem = CVodeCreate(CV_ADAMS, s.ctx);
    if (!s.mem) throw Error("cvode: out of memory");
    check(CVodeInit(s.mem, &cvode_rhs<System>, 0.0, s.y), "CVodeInit");
    check(CVodeSetUserData(s.mem, const_cast<System*>(&sys)), "CVodeSetUserData");
    check(CVodeSStolerances(s.mem, spec.tol, spec.tol), "CVodeSStolerances");
    if (spec.h0 > 0.0) check(CVodeSetInitStep(s.mem, spec.h0), "CVodeSetInitStep");  // else CVODE's own estimate
    check(CVodeSetStopTime(s.mem, spec.t_end), "CVodeSetStopTime");
    s.nls = SUNNonlinSol_FixedPoint(s.y, 0, s.ctx);
    if (!s.nls) throw Error("cvode: out of memory");
    check(CVodeSetNonlinearSolver(s.mem, s.nls), "CVodeSetNonlinearSolver");
    const double t_end = spec.t_end;
    detail::StepStats st;
    auto to_physical = [](const OdeState<double>& x) { return from_ode(x); };
    RunResult r = observe(body.p, field, body.s0, options, detail::grid_of(spec), to_physical, [&](auto& obs) {
      auto try_step = [&](OdeState<double>& x, double& t, double& /*dt*/) {  // CVODE keeps its own history
        sunrealtype reached = t;
        const int flag = CVode(s.mem, t_end, s.y, &reached, CV_ONE_STEP);
        if (flag < 0) throw Error("cvode: step failed at t = " + std::to_string(t) + " (flag " + std::to_string(flag) + ")");
        t = flag == CV_TSTOP_RETURN ? t_end : reached;  // the stop time, exactly
        const double* y = N_VGetArrayPointer(s.y);
        std::copy(y, y + x.size(), x.begin());
        return true;
      };
      return from_ode(detail::controlled_loop<CvodeSays>(x0, spec.h0, t_end, st, obs, try_step));
    });
    r.force_evals = evals;
    st.record(r, t_end);
    return r;
  });
}

}  // namespace bodypoint
