// bodypoint: the core layer's methods and the typed run loops behind `run`.
//
// The field type (one centre at the origin or a list), the spin (B = 0 or not) and the observer
// (none, or invariants and samples) are chosen here, once, before the step loop starts; each
// combination is its own instantiation of the generic loop.
#include "bodypoint/run.hpp"

#include "bodypoint/run_support.hpp"

#include "bodypoint/field.hpp"
#include "bodypoint/rhs.hpp"
#include "bodypoint/rk/run_odeint.hpp"
#ifdef BODYPOINT_HAVE_GSL
#include "bodypoint/rk/run_gsl.hpp"
#endif
#include "bodypoint/splitting/blanes_moan.hpp"
#include "bodypoint/splitting/classic.hpp"
#include "bodypoint/splitting/composition.hpp"
#include "bodypoint/splitting/kahan_li.hpp"
#include "bodypoint/splitting/lie_poisson.hpp"
#include "bodypoint/splitting/mclachlan.hpp"
#include "bodypoint/splitting/sofroniou_spaletta.hpp"
#include "bodypoint/splitting/thesis.hpp"
#include "bodypoint/splitting/sequences.hpp"
#include "bodypoint/splitting/yoshida.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <type_traits>

namespace bodypoint {
namespace {

namespace sp = splitting;
using namespace splitting::ops;
using detail::dispatch;
using detail::observe;

/// True when the scene asks for the published code, index slip included (model.hpp, ForceLaw).
bool reproduces_code(const std::vector<Centre>& centres) {
  for (const Centre& k : centres)
    if (k.law == ForceLaw::thesis_code) return true;
  return false;
}

template <template <class, bool> class Kernel, const auto& Seq, sp::CodeSlip Slip = sp::CodeSlip::none>
RunResult run_splitting(const Body& body, const std::vector<Centre>& centres, const RunSpec& spec,
                        const SampleSink* sink) {
  return dispatch(body, centres, [&](const auto& field, auto spin) {
    using Field = std::decay_t<decltype(field)>;
    using K = Kernel<Field, decltype(spin)::value>;
    K kernel(body.p, field);
    if constexpr (Slip != sp::CodeSlip::none)
      if (reproduces_code(centres)) kernel.slip = Slip;
    auto to_physical = [&kernel](const typename K::state_type& x) { return kernel.to_physical(x); };
    RunResult r = observe(body.p, field, body.s0, spec, sink, to_physical, [&](auto& obs) {
      typename K::state_type x = kernel.initial_state(body.s0);
      sp::integrate<Seq>(kernel, x, spec.h, spec.steps, obs);
      return kernel.to_physical(x);
    });
    r.force_evals = kernel.evals;
    return r;
  });
}

template <const auto& Seq, sp::CodeSlip Slip = sp::CodeSlip::none>
MethodInfo thesis_method(std::string_view name, int order, std::string_view what) {
  return {name, Family::Thesis, order, static_cast<int>(Seq.kicks()), static_cast<int>(Seq.kicks()),
          what, &run_splitting<sp::ThesisKernel, Seq, Slip>};
}

template <const auto& Seq>
MethodInfo lie_method(std::string_view name, int order, std::string_view what) {
  return {name, Family::LiePoisson, order, static_cast<int>(Seq.kicks()),
          static_cast<int>(Seq.kicks_merged()), what, &run_splitting<sp::LiePoissonKernel, Seq>};
}

std::vector<MethodInfo> make_rows() {
  std::vector<MethodInfo> all = {
      {"rk4", Family::Odeint, 4, 4, 4, "classical Runge-Kutta (thesis 2.1; odeint runge_kutta4)",
       &run_odeint_rk4},
      {"ab4", Family::Odeint, 4, 1, 1,
       "Adams-Bashforth 4 started by RK4 (thesis 2.2; odeint adams_bashforth<4>)",
       &run_odeint_ab4},
      {"odeint-dopri5", Family::OdeintAdaptive, 5, 6, 6,
       "Dormand-Prince 5(4) with step-size control (odeint runge_kutta_dopri5), --tol",
       &run_odeint_dopri5},
      {"odeint-rkf78", Family::OdeintAdaptive, 8, 13, 13,
       "Fehlberg 7(8) with step-size control (odeint runge_kutta_fehlberg78), --tol",
       &run_odeint_rkf78},
      {"odeint-bs", Family::OdeintAdaptive, 0, 0, 0,
       "Bulirsch-Stoer extrapolation with order and step control (odeint bulirsch_stoer), --tol",
       &run_odeint_bs},
#ifdef BODYPOINT_HAVE_GSL
      {"gsl-rk8pd", Family::Gsl, 8, 13, 13, "GSL Prince-Dormand 8(7) with step-size control (gsl_odeiv2_step_rk8pd), --tol",
       &run_gsl_rk8pd},
      {"gsl-rkf45", Family::Gsl, 5, 6, 6, "GSL Runge-Kutta-Fehlberg 4(5) with step-size control (gsl_odeiv2_step_rkf45), --tol",
       &run_gsl_rkf45},
#endif
      thesis_method<euler_ops>("thesis-euler", 1, "thesis symplectic Euler, frozen gyroscopic term"),
      thesis_method<verlet_ops>("thesis-verlet", 2, "thesis Verlet (KDK), frozen gyroscopic term"),
      thesis_method<ruth3_ops, sp::CodeSlip::third_v_z>("thesis-ruth3", 3, "thesis Ruth 3, frozen gyroscopic term"),
      thesis_method<y4_ops, sp::CodeSlip::third_v_z>("thesis-fr4", 4, "thesis Forest-Ruth 4 (eq. 2.9-2.10), frozen gyroscopic term"),
      thesis_method<y6_ops, sp::CodeSlip::third_vw_z>("thesis-y6", 6, "thesis Yoshida 6 (table 2.1), frozen gyroscopic term"),
      lie_method<euler_ops>("lp-euler", 1, "exact Lie-Poisson splitting, Lie-Trotter D K"),
      lie_method<verlet_ops>("lp-verlet", 2, "exact Lie-Poisson Strang, kick-drift-kick"),
      lie_method<strang_ops>("lp-verlet-dkd", 2, "exact Lie-Poisson Strang, drift-kick-drift"),
      lie_method<ruth3_ops>("lp-ruth3", 3, "exact Lie-Poisson, Ruth 1983 third order"),
      lie_method<y4_ops>("lp-y4", 4, "exact Lie-Poisson, Yoshida/Forest-Ruth 4 (3 stages)"),
      lie_method<bm4_ops>("lp-bm4", 4, "exact Lie-Poisson, Blanes-Moan 2002 S6 (6 stages)"),
      lie_method<rkn4_ops>("lp-rkn4", 4, "exact Lie-Poisson, Blanes-Moan 2002 SRKN_6^b (RKN, 6 stages)"),
      lie_method<rkn6_ops>("lp-rkn6", 6, "exact Lie-Poisson, Blanes-Moan 2002 SRKN_11^b (RKN, 11 stages)"),
      lie_method<y6_ops>("lp-y6", 6, "exact Lie-Poisson, Yoshida 6 triple jump (thesis table 2.1)"),
      lie_method<kl6_ops>("lp-kl6", 6, "exact Lie-Poisson, Kahan-Li 1997 p6 s9"),
      lie_method<y8_ops>("lp-y8", 8, "exact Lie-Poisson, Yoshida 8 triple jump (27 stages)"),
      lie_method<y8d_ops>("lp-y8d", 8, "exact Lie-Poisson, Yoshida 1990 solution D (15 stages)"),
      lie_method<mcl8_ops>("lp-mcl8", 8, "exact Lie-Poisson, McLachlan 1995 p8 s15"),
      lie_method<kl8_ops>("lp-kl8", 8, "exact Lie-Poisson, Kahan-Li 1997 p8 s17"),
      lie_method<ss10_ops>("lp-ss10", 10, "exact Lie-Poisson, Sofroniou-Spaletta 2005 p10 s35"),
  };
  return all;
}

}  // namespace

const std::vector<MethodInfo>& core_methods() {
  static const std::vector<MethodInfo> rows = make_rows();
  return rows;
}

namespace {
/// Per-step tolerance floor of the step-size-controlled methods: a step's own rounding is ~1e-16.
constexpr double kMinStepTolerance = 1e-15;
}  // namespace

Health assess(const RunResult& r) {
  const State& f = r.final;
  const bool finite = f.R.allFinite() && f.v.allFinite() && f.w.allFinite();
  const InvariantStats* inv = r.invariants ? &*r.invariants : nullptr;
  const bool fell = inv && inv->min_r_attracting < kCollisionFraction * inv->r0_attracting;
  std::string why;
  if (!finite) why = "the state became non-finite (NaN/inf)";
  else if (inv && !(std::isfinite(inv->max_rel_dE) && std::isfinite(inv->max_rel_dK2sq) && std::isfinite(inv->max_abs_dK2Q)))
    why = "an invariant became non-finite";
  else if (inv && inv->max_rel_dE > kDivergedEnergy)
    why = "the relative energy error reached " + detail::short_number(inv->max_rel_dE) + " (above 1)";
  if (why.empty()) return {"ok", ""};
  if (fell)
    return {"collision", why + " after a fall onto an attracting centre (closest approach " +
                             detail::short_number(inv->min_r_attracting) + " from a start at " +
                             detail::short_number(inv->r0_attracting) + ")"};
  return {"diverged", why};
}

RunResult run(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres,
              const RunSpec& spec, const SampleSink* sink) {
  validate(Scene{centres, {body}});
  if (!std::isfinite(spec.h) || spec.h <= 0.0)
    throw Error("step size h must be a finite number > 0, got " + std::to_string(spec.h));
  if (spec.every < 1) throw Error("--every must be >= 1");
  if (is_time_transformed(method) && non_coulomb(centres))
    throw Error(std::string(method.name) + " assumes Coulomb's law (its time transformation is built on -A/|R|); the "
                "thesis code's force law runs with the fixed-step, Runge-Kutta and step-size-controlled methods");
  // Time-transformed methods run to t_end when it is given, otherwise for spec.steps fictitious steps.
  if (is_time_transformed(method)) return method.run(body, centres, spec, sink);
  if (spec.steps < 1) throw Error("number of steps must be >= 1");
  if (is_adaptive(method)) {
    RunSpec s = spec;
    if (s.t_end == 0.0) s.t_end = spec.h * static_cast<double>(spec.steps);
    if (!std::isfinite(s.t_end) || s.t_end <= 0.0) throw Error("end time must be a finite number > 0");
    if (!std::isfinite(s.tol) || s.tol <= 0.0) throw Error("--tol must be a finite number > 0");
    if (s.tol < kMinStepTolerance)
      throw Error("--tol " + detail::short_number(s.tol) + " is below what double precision can deliver (a step's rounding "
                  "is ~1e-16 relative; the smallest tolerance taken is 1e-15)");
    return method.run(body, centres, s, sink);
  }
  return method.run(body, centres, spec, sink);
}

}  // namespace bodypoint
