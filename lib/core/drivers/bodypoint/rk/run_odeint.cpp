// bodypoint: Boost.Odeint run loops (fixed-step RK4/AB4 and the step-size-controlled steppers).
#include "bodypoint/rk/run_odeint.hpp"

#include "bodypoint/detail/equations.hpp"
#include "bodypoint/rk/odeint.hpp"
#include "bodypoint/detail/run_support.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <type_traits>

namespace bodypoint {
namespace {

using detail::dispatch;
using detail::observe;

/// The fixed-step loop. Built into the library, GCC kept the right-hand side out of line here (it
/// is called from several odeint loops in this unit), and an RK4 step cost 123-128 ns on table 3.1
/// against 65-80 ns for odeint driven directly from a small unit (bench_steps BM_OdeintDirect).
/// `flatten` inlines everything the RK4 loop calls, as the small unit does: 70 ns. AB4 is kept
/// plain: flattened it gets slower (33 -> 46 ns per step), its RK4 start-up being inlined too.
template <class Stepper, class System, class Observer>
OdeState<double> fixed_step_body(System& sys, OdeState<double> x, double h, long n, Observer& obs) {
  Stepper stepper;
  for (long i = 0; i < n; ++i) {
    stepper.do_step(std::ref(sys), x, static_cast<double>(i) * h, h);
    if constexpr (Observer::active) obs(i + 1, x);
    if (!splitting::poll(obs, i + 1)) break;
  }
  return x;
}
template <class Stepper, class System, class Observer>
[[gnu::noinline, gnu::flatten]] OdeState<double> fixed_step_flat(System sys, OdeState<double> x, double h, long n,
                                                                 Observer& obs) {
  return fixed_step_body<Stepper>(sys, x, h, n, obs);
}
template <class Stepper, class System, class Observer>
[[gnu::noinline]] OdeState<double> fixed_step_plain(System sys, OdeState<double> x, double h, long n, Observer& obs) {
  return fixed_step_body<Stepper>(sys, x, h, n, obs);
}
template <class Stepper, class System, class Observer>
OdeState<double> fixed_step_loop(const System& sys, OdeState<double> x, double h, long n, Observer& obs) {
  if constexpr (std::is_same_v<Stepper, rk::Rk4>) return fixed_step_flat<Stepper>(sys, x, h, n, obs);
  else return fixed_step_plain<Stepper>(sys, x, h, n, obs);
}

template <class Stepper>
RunResult run_odeint(const Body& body, const std::vector<Centre>& centres, const Advance& how,
                     const RunOptions& options) {
  const auto& fixed = std::get<FixedSteps>(how);
  return dispatch(body, centres, [&](const auto& field, auto spin) {
    using Field = std::decay_t<decltype(field)>;
    long evals = 0;
    EquationsOfMotion<Field, decltype(spin)::value> sys{body.p, field, &evals};
    auto to_physical = [](const OdeState<double>& x) { return from_ode(x); };
    RunResult r = observe(body.p, field, body.s0, options, detail::grid_of(fixed), to_physical, [&](auto& obs) {
      return from_ode(fixed_step_loop<Stepper>(sys, to_ode(body.s0), fixed.h, fixed.steps, obs));
    });
    r.force_evals = evals;
    return r;
  });
}

/// How the controlled-step driver words an odeint stepper's failures.
struct OdeintSays {
  static std::string stalled(double t, double taken) {
    return "the step stopped advancing time at t = " + detail::short_number(t) + " (accepted step " +
           detail::short_number(taken) + "): the tolerance is below what double precision resolves, "
           "or the body fell onto a centre";
  }
  static std::string too_many(double t, double t_end) {
    return "more than 2e8 accepted steps before t_end = " + detail::short_number(t_end) + " (reached t = " +
           detail::short_number(t) + "); loosen the tolerance tol or shorten t_end";
  }
  static std::string collapsed(double t) {
    return "adaptive step size collapsed at t = " + std::to_string(t) + " (tolerance too tight?)";
  }
};

/// Step-size-controlled odeint stepper from t = 0 to t_end, hitting t_end exactly (the last
/// trial step is cut to the remaining time). The observer sees every accepted step.
template <class Controlled>
RunResult run_odeint_adaptive(const Body& body, const std::vector<Centre>& centres,
                              const Advance& how, const RunOptions& options) {
  const auto& spec = std::get<ControlledSteps>(how);
  return dispatch(body, centres, [&](const auto& field, auto spin) {
    using Field = std::decay_t<decltype(field)>;
    long evals = 0;
    EquationsOfMotion<Field, decltype(spin)::value> sys{body.p, field, &evals};
    auto to_physical = [](const OdeState<double>& x) { return from_ode(x); };
    const double t_end = spec.t_end;
    detail::StepStats st;
    RunResult r = observe(body.p, field, body.s0, options, detail::grid_of(spec), to_physical, [&](auto& obs) {
      Controlled stepper = rk::make_controlled<Controlled>(spec.tol);
      auto try_step = [&](OdeState<double>& x, double& t, double& dt) __attribute__((always_inline)) {
        const bool final_step = t + dt >= t_end;
        if (final_step) dt = t_end - t;
        if (stepper.try_step(std::ref(sys), x, t, dt) != boost::numeric::odeint::success) return false;
        if (final_step) t = t_end;  // exact end time, not t_before + dt rounded
        return true;
      };
      return from_ode(detail::controlled_loop<OdeintSays>(to_ode(body.s0), spec.h0, t_end, st, obs, try_step));
    });
    r.force_evals = evals;
    st.record(r, t_end);
    return r;
  });
}

}  // namespace

RunResult run_odeint_rk4(const Body& b, const std::vector<Centre>& c, const Advance& s, const RunOptions& k) {
  return run_odeint<rk::Rk4>(b, c, s, k);
}
RunResult run_odeint_ab4(const Body& b, const std::vector<Centre>& c, const Advance& s, const RunOptions& k) {
  return run_odeint<rk::Ab4>(b, c, s, k);
}
RunResult run_thesis_ab4(const Body& b, const std::vector<Centre>& c, const Advance& s, const RunOptions& k) {
  return run_odeint<rk::ThesisAb4>(b, c, s, k);
}
RunResult run_odeint_dopri5(const Body& b, const std::vector<Centre>& c, const Advance& s, const RunOptions& k) {
  return run_odeint_adaptive<rk::Dopri5>(b, c, s, k);
}
RunResult run_odeint_rkf78(const Body& b, const std::vector<Centre>& c, const Advance& s, const RunOptions& k) {
  return run_odeint_adaptive<rk::Rkf78>(b, c, s, k);
}
RunResult run_odeint_bs(const Body& b, const std::vector<Centre>& c, const Advance& s, const RunOptions& k) {
  return run_odeint_adaptive<rk::BulirschStoer>(b, c, s, k);
}

}  // namespace bodypoint
