// bodypoint: the core layer's methods and the typed run loops behind `run`.
//
// The field type (one centre at the origin or a list), the spin (B = 0 or not) and the observer
// (none, or invariants and samples) are chosen here, once, before the step loop starts; each
// combination is its own instantiation of the generic loop.
#include "bodypoint/run.hpp"

#include "bodypoint/detail/run_support.hpp"

#include "bodypoint/far_field.hpp"
#include "bodypoint/field.hpp"
#include "bodypoint/rhs.hpp"
#include "bodypoint/rk/run_odeint.hpp"
#ifdef BODYPOINT_HAVE_GSL
#include "bodypoint/rk/run_gsl.hpp"
#include "bodypoint/rk/run_sundials.hpp"
#endif
#include "bodypoint/splitting/catalogue.hpp"
#include "bodypoint/splitting/kepler_split.hpp"
#include "bodypoint/splitting/lie_poisson.hpp"
#include "bodypoint/splitting/thesis.hpp"
#include "bodypoint/detail/run_parts.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iterator>
#include <limits>
#include <numbers>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>

namespace bodypoint {
namespace {

namespace sp = splitting;
using detail::dispatch;
using detail::observe;

/// True when the scene asks for the published code, index slip included (model.hpp, ForceLaw).
bool reproduces_code(const std::vector<Centre>& centres) {
  for (const Centre& k : centres)
    if (k.law == ForceLaw::thesis_code) return true;
  return false;
}

template <template <class, bool> class Kernel, const auto& Seq, sp::CodeSlip Slip = sp::CodeSlip::none>
RunResult run_splitting(const Body& body, const std::vector<Centre>& centres, const Advance& how,
                        const RunOptions& options) {
  const auto& fixed = std::get<FixedSteps>(how);
  return dispatch(body, centres, [&](const auto& field, auto spin) {
    using Field = std::decay_t<decltype(field)>;
    using K = Kernel<Field, decltype(spin)::value>;
    K kernel(body.p, field);
    if constexpr (Slip != sp::CodeSlip::none)
      if (reproduces_code(centres)) kernel.slip = Slip;
    auto to_physical = [&kernel](const typename K::state_type& x) { return kernel.to_physical(x); };
    RunResult r = observe(body.p, field, body.s0, options, detail::grid_of(fixed), to_physical, [&](auto& obs) {
      typename K::state_type x = kernel.initial_state(body.s0);
      sp::integrate<Seq>(kernel, x, fixed.h, fixed.steps, obs);
      return kernel.to_physical(x);
    });
    r.force_evals = kernel.evals;
    return r;
  });
}

/// The row of a thesis-family method from its entry in ThesisTables (catalogue.hpp).
template <class E>
MethodInfo thesis_row(int batch_kernel) {
  using T = typename E::type;
  constexpr const auto& seq = sp::ops_of<T>;
  constexpr sp::CodeSlip slip = [] {
    if constexpr (std::is_same_v<std::remove_cv_t<decltype(E::extra)>, sp::CodeSlip>) {
      return E::extra;
    } else {
      return sp::CodeSlip::none;
    }
  }();
  const int k = static_cast<int>(seq.kicks());
  MethodInfo m{"thesis-" + std::string(E::tag), Family::Thesis, T::order, k, k,
               sp::describe<T>("thesis, frozen gyroscopic term"),
               &run_splitting<sp::ThesisKernel, seq, slip>, nullptr, batch_kernel};
  m.symmetric = sp::ops_of<T>.symmetric();
  return m;
}

/// The row of an exact Lie-Poisson method from its entry in LiePoissonTables (catalogue.hpp).
template <class E>
MethodInfo lie_row(int batch_kernel) {
  using T = typename E::type;
  constexpr const auto& seq = sp::ops_of<T>;
  MethodInfo m{"lp-" + std::string(E::tag), Family::LiePoisson, T::order, static_cast<int>(seq.kicks()),
               static_cast<int>(seq.kicks_merged()),
               sp::describe<T>("exact Lie-Poisson"),
               &run_splitting<sp::LiePoissonKernel, seq>, nullptr, batch_kernel};
  m.table = E::tag;
  m.symmetric = seq.symmetric();
  return m;
}

/// The Kepler split's assumption: Coulomb's law (its Kepler flow is built on -A/|R|).
std::string kepler_split_check(const MethodInfo& m, const Body& /*body*/, const std::vector<Centre>& centres) {
  if (non_coulomb(centres)) return m.name + " assumes Coulomb's law (its Kepler flow is built on -A/|R|)";
  return "";
}

/// The Kepler split of table T: two parts for one centre, three (the other centres' kicks) for several.
template <sp::TableType T>
RunResult run_kepler_split(const Body& body, const std::vector<Centre>& centres, const Advance& how,
                           const RunOptions& options) {
  static_assert(sp::is_dkd_composition(T::table), "the three-part Kepler split needs a DKD composition");
  if (centres.size() == 1) return run_splitting<sp::KeplerSplitKernel, sp::ops_of<T>>(body, centres, how, options);
  return run_splitting<sp::KeplerSplitKernel, sp::three_part_ops_of<T>>(body, centres, how, options);
}

/// The row of a Kepler-split method from its entry in KeplerSplitTables (catalogue.hpp).
template <class E>
MethodInfo kepler_row() {
  using T = typename E::type;
  const int k = static_cast<int>(sp::ops_of<T>.kicks());
  MethodInfo m{"kep-" + std::string(E::tag), Family::KeplerSplit, T::order, k, k,
               sp::describe<T>("Kepler split (a stage is a Kepler solve about the first centre)"),
               &run_kepler_split<T>, &kepler_split_check};
  m.table = E::tag;
  m.symmetric = sp::ops_of<T>.symmetric();
  return m;
}

/// The far-field collocation's assumption: Coulomb's law (its force is -A (R - c)/|R - c|^3).
std::string far_field_check(const MethodInfo& m, const Body& /*body*/, const std::vector<Centre>& centres) {
  if (non_coulomb(centres)) return m.name + " assumes Coulomb's law";
  return "";
}

/// far-ip: fixed steps of the far-field collocation (far_field.hpp).
RunResult run_far_field(const Body& body, const std::vector<Centre>& centres, const Advance& how,
                        const RunOptions& options) {
  const auto& fixed = std::get<FixedSteps>(how);
  return dispatch(body, centres, [&](const auto& field, auto /*spin*/) {
    far_field::Stepper stepper(body.p, centres);
    auto to_physical = [&body](const Momenta& q) { return to_state(body.p, q); };
    RunResult r = observe(body.p, field, body.s0, options, detail::grid_of(fixed), to_physical, [&](auto& obs) {
      Momenta x = to_momenta(body.p, body.s0);
      for (long i = 0; i < fixed.steps; ++i) {
        stepper.step(x, fixed.h);
        if constexpr (std::decay_t<decltype(obs)>::active) {
          if (obs.wants_inside())
            for (int j = 1; j <= stepper.inner_points(); ++j) {
              double tau = 0.0;
              const Momenta inner = stepper.at_point(j, tau);
              obs.inside(i + 1, static_cast<double>(i) * fixed.h + tau, to_state(body.p, inner));
            }
          obs(i + 1, x);
        }
        if (!sp::poll(obs, i + 1)) break;
      }
      return to_state(body.p, x);
    });
    r.force_evals = stepper.evals;
    return r;
  });
}

std::vector<MethodInfo> make_rows() {
  std::vector<MethodInfo> all = {
      {"rk4", Family::Odeint, 4, 4, 4, "classical Runge-Kutta (thesis 2.1; odeint runge_kutta4)",
       &run_odeint_rk4, nullptr, sp::kBatchRk4},
      {"ab4", Family::Odeint, 4, 1, 1,
       "Adams-Bashforth 4 started by RK4 (thesis 2.2; odeint adams_bashforth<4>)",
       &run_odeint_ab4},
      {"ab4-thesis", Family::Odeint, 4, 4, 4,
       "Adams-Bashforth 4 as the thesis's code runs it: Ab4's states, the four right-hand sides evaluated again "
       "every step (thesis table 4.1)",
       &run_thesis_ab4},
      {"odeint-dopri5", Family::OdeintAdaptive, 5, 6, 6,
       "Dormand-Prince 5(4) with step-size control (odeint runge_kutta_dopri5); a tolerance per step",
       &run_odeint_dopri5},
      {"odeint-rkf78", Family::OdeintAdaptive, 8, 13, 13,
       "Fehlberg 7(8) with step-size control (odeint runge_kutta_fehlberg78); a tolerance per step",
       &run_odeint_rkf78},
      {"odeint-bs", Family::OdeintAdaptive, 0, 0, 0,
       "Bulirsch-Stoer extrapolation with order and step control (odeint bulirsch_stoer); a tolerance per step",
       &run_odeint_bs},
#ifdef BODYPOINT_HAVE_GSL
      {"gsl-rk8pd", Family::Gsl, 8, 13, 13, "GSL Prince-Dormand 8(7) with step-size control (gsl_odeiv2_step_rk8pd); a tolerance per step",
       &run_gsl_rk8pd},
      {"gsl-rkf45", Family::Gsl, 5, 6, 6, "GSL Runge-Kutta-Fehlberg 4(5) with step-size control (gsl_odeiv2_step_rkf45); a tolerance per step",
       &run_gsl_rkf45},
#endif
#ifdef BODYPOINT_HAVE_SUNDIALS
      {"cvode-adams", Family::Sundials, 0, 0, 0,
       "SUNDIALS CVODE variable-order Adams-Moulton (1-12) with fixed-point iteration and step-size control; a "
       "tolerance per step (rtol = atol)",
       &run_cvode_adams},
#endif
  };
  std::size_t table = 0;
  sp::for_each(sp::ThesisTables{}, [&]<class E>() { all.push_back(thesis_row<E>(sp::batch_thesis_kernel(table++))); });
  table = 0;
  sp::for_each(sp::LiePoissonTables{}, [&]<class E>() { all.push_back(lie_row<E>(sp::batch_lie_kernel(table++))); });
  sp::for_each(sp::KeplerSplitTables{}, [&all]<class E>() { all.push_back(kepler_row<E>()); });
  all.push_back({"far-ip", Family::FarField, 0, 0, 0,
                 "far-field collocation: Chebyshev-Picard iteration in the interaction picture of the exact drift "
                 "(Bai and Junkins 2011); a step may turn the spin by tens of radians",
                 &run_far_field, &far_field_check});
  for (MethodInfo& m : all) m.traits = catalogue_traits(m.family);
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

void check_energy_bound(double max_energy_error) {
  if (!(max_energy_error > 0.0))
    throw Error("the bound on the energy error must be a number > 0 (infinity: no bound), got " +
                detail::short_number(max_energy_error));
}

namespace {

/// Each family's two names (MethodTraits::family_name, family_key), one row per Family in its order.
struct FamilyNames {
  Family family;
  std::string_view name, key;
  std::string_view geometry;  ///< what its flows preserve (MethodTraits::geometry)
};
constexpr FamilyNames kFamilyNames[] = {
    {Family::Thesis, "thesis drift/kick", "thesis",
     "not symplectic for B != 0 (the frozen gyroscopic term)"},
    {Family::LiePoisson, "exact Lie-Poisson", "lie-poisson",
     "Poisson (symplectic), |K2|^2 exact, K2Q with one centre"},
    {Family::KeplerSplit, "Kepler split", "kepler-split",
     "Poisson (symplectic), |K2|^2 exact, K2Q with one centre"},
    {Family::Odeint, "Boost.Odeint fixed step", "odeint",
     "none"},
    {Family::OdeintAdaptive, "Boost.Odeint adaptive", "odeint-adaptive",
     "none"},
    {Family::Gsl, "GSL adaptive", "gsl",
     "none"},
    {Family::TimeTransformed, "time-transformed", "time-transformed",
     "symplectic in the extended phase space, |K2|^2 exact, K2Q with one centre"},
    {Family::Regularised, "regularised", "regularised",
     "exact flow (material point, one centre)"},
    {Family::Extrapolated, "logH extrapolated", "extrapolated",
     "none (an extrapolated symmetric leapfrog)"},
    {Family::FarField, "far-field collocation", "far-field",
     "none (a collocation)"},
    {Family::Sundials, "SUNDIALS CVODE", "sundials",
     "none"},
};
constexpr bool one_row_per_family_in_order() {
  for (std::size_t i = 0; i < std::size(kFamilyNames); ++i)
    if (static_cast<std::size_t>(kFamilyNames[i].family) != i) return false;
  return std::size(kFamilyNames) == static_cast<std::size_t>(Family::Sundials) + 1;
}
static_assert(one_row_per_family_in_order(), "kFamilyNames: one row per Family, in the enum's order");

/// far-ip's first step turns the spin by at most this many turns (docs/measurements.md, "Tuned constants").
constexpr double kFarFieldTurns = 1.0;

double spin_orbit_period(const Body& b) {
  const double rate = std::abs(b.p.B) * to_momenta(b.p, b.s0).K1.norm() / b.p.D();
  return rate > 0.0 ? 2.0 * std::numbers::pi / rate : std::numeric_limits<double>::infinity();
}

/// A fixed step: a sixteenth of the run, at most one turn of the spin about K1.
double fixed_first_step(const Body& b, const std::vector<Centre>&, double t_end) {
  return std::min(t_end / 16.0, spin_orbit_period(b));
}

/// A time transformation's ds: dt = ds r/|A| near a centre advances the orbit by ds v/|A| radians, one a step.
double fictitious_first_step(const Body& b, const std::vector<Centre>& centres, double) {
  const double v = b.s0.v.norm();
  double a = 0.0;
  for (const Centre& c : centres) a += std::abs(c.A);
  return (v > 0.0 && a > 0.0) ? a / v : 0.1;
}

/// KS's fictitious time: one sub-step of the exact flow (sqrt(2 |h|) ds = 1, ks.hpp).
double regularised_first_step(const Body& b, const std::vector<Centre>& centres, double) {
  const double mu = centres.front().A / b.p.m;
  const double h = 0.5 * b.s0.v.squaredNorm() - mu / (b.s0.R - centres.front().c).norm();
  return h != 0.0 ? 1.0 / std::sqrt(2.0 * std::abs(h)) : 1.0;
}

/// far-ip's step is set by the field's slow scale (far_field.hpp): the time the guiding centre takes to cover
/// its least distance to the nearest centre, at most kFarFieldTurns turns of the spin; a step too long for the
/// field is refused and halved.
double far_field_first_step(const Body& b, const std::vector<Centre>& centres, double t_end) {
  const Helix helix = helix_of(b.p, to_momenta(b.p, b.s0));
  double r = std::numeric_limits<double>::infinity();
  for (const Centre& c : centres) r = std::min(r, path_distance(helix, c.c, t_end));
  const double v = helix.velocity.norm();
  return std::min({t_end, v > 0.0 ? r / v : t_end, kFarFieldTurns * spin_orbit_period(b)});
}

}  // namespace

std::string geometry_text(const MethodInfo& m) {
  std::string g(m.traits.geometry);
  if (!m.table.empty() || m.family == Family::Thesis) g += m.symmetric ? "; symmetric" : "; not symmetric";
  return g;
}

MethodTraits catalogue_traits(Family f) {
  const FamilyNames& names = kFamilyNames[static_cast<std::size_t>(f)];
  MethodTraits t{.family_name = names.name, .family_key = names.key, .geometry = names.geometry, .first_step = fixed_first_step};
  switch (f) {
    case Family::Thesis:
      t.frozen_gyroscopic_term = true;
      t.in_fixed_set = true;
      break;
    case Family::LiePoisson:
      t.free_flight_spin_exact = true;  // the exact drift rotates the spin; without a force nothing else acts on it
      t.in_fixed_set = true;
      break;
    case Family::KeplerSplit:
      t.orbit_exact = true;
      t.free_flight_spin_exact = true;
      break;
    case Family::Odeint:
      t.peer = true;
      t.third_party = true;
      t.in_fixed_set = true;
      break;
    case Family::OdeintAdaptive:
    case Family::Gsl:
    case Family::Sundials:
      t.stepping = Stepping::controlled;
      t.search = SearchStrategy::none;
      t.peer = true;
      t.third_party = true;
      break;
    case Family::TimeTransformed:
      t.stepping = Stepping::fictitious;
      t.free_flight_spin_exact = true;
      t.takes_omega_c = true;
      t.first_step = fictitious_first_step;
      break;
    case Family::Regularised:
      t.stepping = Stepping::fictitious;
      t.search = SearchStrategy::exact_pair;
      t.orbit_exact = true;
      t.exact_in_fictitious_time = true;
      t.first_step = regularised_first_step;
      break;
    case Family::Extrapolated:
      t.stepping = Stepping::controlled;
      t.search = SearchStrategy::none;
      t.peer = true;
      t.macro_steps = true;
      break;
    case Family::FarField:
      t.search = SearchStrategy::field_pair;
      t.macro_steps = true;
      t.cost_set_by = "points x sweeps";  // far_field.hpp
      t.first_step = far_field_first_step;
      break;
  }
  return t;
}

Advance advance_to(const MethodInfo& m, double step, double end, double h0) {
  // A controlled method's step is its tolerance per step, its control starting at h0.
  if (is_step_controlled(m)) return advance_of(m, {.step = h0, .end = end, .tol = step});
  return advance_of(m, {.step = step, .end = end});
}

Advance advance_of(const MethodInfo& m, const RunAt& r) {
  switch (m.traits.stepping) {
    case Stepping::fictitious:
      return r.end > 0.0 ? FictitiousSteps{r.step, EndTime{r.end}, r.dt_out} : FictitiousSteps{r.step, StepCount{r.steps}, r.dt_out};
    case Stepping::controlled: {
      const double t = r.end > 0.0 ? r.end : r.step * static_cast<double>(r.steps);
      return ControlledSteps{std::min(r.step > 0.0 ? r.step : kControlledFirstStep, t), t, r.tol, r.dt_out};
    }
    case Stepping::fixed: break;
  }
  FixedSteps f{r.step, r.steps};
  if (r.end > 0.0 && r.grid == FixedGrid::landing) f = fixed_steps_to(r.end, r.step);
  if (r.end > 0.0 && r.grid == FixedGrid::nearest) {
    const long n = std::max(1L, std::lround(r.end / r.step));
    f = FixedSteps{r.end / static_cast<double>(n), n};
  }
  f.dt_out = r.dt_out;
  return f;
}

bool lands_on_output_times(const MethodInfo& m) { return is_time_transformed(m); }
bool takes_tolerance_per_step(const MethodInfo& m) { return is_step_controlled(m); }
bool is_exact_flow(const MethodInfo& m) { return m.traits.exact_in_fictitious_time; }
bool keeps_order_with_spin(const MethodInfo& m) { return !m.traits.frozen_gyroscopic_term; }
bool refines_by_step(const MethodInfo& m) {
  return !is_step_controlled(m) && m.traits.search != SearchStrategy::field_pair;
}

std::string_view step_name(const MethodInfo& m) {
  return is_step_controlled(m) ? "tol" : is_time_transformed(m) ? "ds" : "h";
}

std::string_view step_quantity(const MethodInfo& m) {
  return is_step_controlled(m) ? "the tolerance per step tol" : is_time_transformed(m) ? "the fictitious step ds" : "the step h";
}

std::string_view stepping_name(const MethodInfo& m) {
  return is_step_controlled(m) ? "controlled" : is_time_transformed(m) ? "fictitious" : "fixed";
}

bool takes_time_step_constant(const MethodInfo& m) { return m.traits.takes_omega_c; }

double time_step_constant_of(const MethodInfo& m, double c) {
  return takes_time_step_constant(m) ? c : std::numeric_limits<double>::quiet_NaN();
}

int effective_order(const MethodInfo& m, const Body& b) {
  if (m.traits.frozen_gyroscopic_term && b.p.B != 0.0) return 1;  // the gyroscopic term frozen (README, findings)
  return m.order;
}

std::string stages_text(const MethodInfo& m) {
  return is_step_controlled(m) || !m.traits.cost_set_by.empty() ? "-" : std::to_string(m.stages);
}

std::string evals_per_step_text(const MethodInfo& m) {
  return is_step_controlled(m)          ? "adaptive"
         : !m.traits.cost_set_by.empty() ? std::string(m.traits.cost_set_by)
                                          : std::to_string(m.evals_per_step);
}

double search_first_step(const MethodInfo& m, const Body& b, const std::vector<Centre>& centres, double t_end) {
  return m.traits.first_step(b, centres, t_end);
}

Checks checks_for(const MethodInfo& m, const std::vector<Centre>& centres, double max_energy_error) {
  Checks c;
  c.max_energy_error = max_energy_error;
  c.energy_is_integral = !non_coulomb(centres);
  c.orbit_exact = m.traits.orbit_exact;
  const bool free_flight = std::all_of(centres.begin(), centres.end(), [](const Centre& k) { return k.A == 0.0; });
  c.spin_exact = free_flight && m.traits.free_flight_spin_exact;
  c.macro_steps = m.traits.macro_steps;
  return c;
}

Health assess(const RunResult& r, const Checks& checks) {
  const State& f = r.final;
  const bool finite = is_finite(f);
  const InvariantStats* inv = r.invariants ? &*r.invariants : nullptr;
  const bool fell = inv && inv->min_r_attracting < kCollisionFraction * inv->r0_attracting;
  const bool energy = inv && checks.energy_is_integral;
  Outcome outcome = Outcome::diverged;
  std::string why;
  if (!finite) why = "the state became non-finite (NaN/inf)";
  else if (inv && !(std::isfinite(inv->max_rel_dE) && std::isfinite(inv->max_rel_dK2sq) && std::isfinite(inv->max_abs_dK2Q)))
    why = "an invariant became non-finite";
  else if (energy && inv->max_rel_dE > kDivergedEnergy)
    why = "the relative energy error reached " + detail::short_number(inv->max_rel_dE) + " (above 1)";
  else if (inv && !checks.spin_exact && !checks.macro_steps && inv->max_spin_angle > kMaxSpinAngle) {
    outcome = Outcome::unresolved;
    why = "a step turned the spin by " + detail::short_number(inv->max_spin_angle) +
          " rad about K1 (more than pi: the spin-orbit rotation is not resolved)";
  } else if (inv && !checks.orbit_exact && !checks.macro_steps && inv->min_turn_cos < std::cos(kMaxTurnAngle)) {
    outcome = Outcome::unresolved;
    why = "a step turned the direction to a centre by " + detail::short_number(std::acos(std::max(-1.0, inv->min_turn_cos))) +
          " rad (more than pi/2: the encounter is not resolved)";
  } else if (energy && inv->max_rel_dE > checks.max_energy_error) {
    outcome = Outcome::inaccurate;
    why = "the relative energy error reached " + detail::short_number(inv->max_rel_dE) + " (above the bound " +
          detail::short_number(checks.max_energy_error) + ")";
  }
  if (why.empty()) return {Outcome::ok, ""};
  if (fell)
    return {Outcome::collision, why + " after a fall onto an attracting centre (closest approach " +
                             detail::short_number(inv->min_r_attracting) + " from a start at " +
                             detail::short_number(inv->r0_attracting) + ")"};
  return {outcome, why};
}

std::string refusal(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres) {
  return m.check ? m.check(m, body, centres) : std::string();
}

void check(const Advance& how) {
  std::visit(
      [](const auto& a) {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, FixedSteps>) {
          require_positive(a.h, "the step h");
          require_count(a.steps, "the number of steps");
        } else if constexpr (std::is_same_v<A, FictitiousSteps>) {
          require_positive(a.ds, "the fictitious step ds");
          if (a.end.index() == 0) require_positive(a.t_end(), "the end time t_end");
          else require_count(a.steps(), "the number of fictitious steps");
          require_count(a.group, "the steps a fictitious step is taken as (group)");
          if (a.group > 1 && a.dt_out > 0.0)
            throw Error("a fictitious step taken as " + std::to_string(a.group) +
                        " (group) has no output times dt_out: its states between steps would come from the whole step");
        } else if constexpr (std::is_same_v<A, ControlledSteps>) {
          require_positive(a.h0, "the first trial step h0");
          require_positive(a.t_end, "the end time t_end");
          require_positive(a.tol, "the tolerance per step tol");
          if (a.tol < kMinStepTolerance)
            throw Error("the tolerance per step tol " + detail::short_number(a.tol) + " is below what double "
                        "precision can deliver (a step's rounding is ~1e-16 relative; the smallest taken is 1e-15)");
        } else {
          require_positive(a.t_end, "the end time t_end");
          require_non_negative(a.first_step, "the planned first step first_step");
        }
        require_non_negative(a.dt_out, "the output interval dt_out");
      },
      how);
}

bool is_backward(const Advance& how) {
  return std::visit(
      [](const auto& a) {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, FixedSteps>) return a.h < 0.0;
        else if constexpr (std::is_same_v<A, FictitiousSteps>) return a.end.index() == 0 ? a.t_end() < 0.0 : a.ds < 0.0;
        else return a.t_end < 0.0;
      },
      how);
}

Advance forwards(Advance how) {
  // An end time that is not a finite number keeps its sign: check() then names the value given (-inf, not inf).
  const auto size = [](double t) { return std::isfinite(t) ? std::abs(t) : t; };
  std::visit(
      [&size](auto& a) {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, FixedSteps>) {
          a.h = std::abs(a.h);
        } else if constexpr (std::is_same_v<A, FictitiousSteps>) {
          a.ds = std::abs(a.ds);
          if (a.end.index() == 0) a.end = EndTime{size(a.t_end())};
        } else if constexpr (std::is_same_v<A, ControlledSteps>) {
          a.h0 = std::abs(a.h0);
          a.t_end = size(a.t_end);
        } else {
          a.t_end = size(a.t_end);
        }
      },
      how);
  return how;
}

Advance backwards(Advance how) {
  how = forwards(std::move(how));
  std::visit(
      [](auto& a) {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, FixedSteps>) a.h = -a.h;
        else if constexpr (std::is_same_v<A, FictitiousSteps>) {
          if (a.end.index() == 0) a.end = EndTime{-a.t_end()};
          else a.ds = -a.ds;
        } else {
          a.t_end = -a.t_end;
        }
      },
      how);
  return how;
}

double output_interval(const Advance& how) {
  return std::visit([](const auto& a) -> double { return a.dt_out; }, how);
}

long check_every(long every) { return require_count(every, "every (the sampling interval in steps)"); }

void check(const RunOptions& options) {
  check_every(options.every);
  if (std::isnan(options.omega_c) || options.omega_c == std::numeric_limits<double>::infinity())
    throw Error("the time-step constant omega_c must be a finite number >= 0 (< 0: chosen from the scene), got " +
                detail::short_number(options.omega_c));
}

void check_takes(const MethodInfo& m, const Advance& how) {
  const char* takes = is_time_transformed(m) ? "FictitiousSteps" : is_step_controlled(m) ? "ControlledSteps" : "FixedSteps";
  const bool ok = std::visit(
      [&m](const auto& a) {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, FixedSteps>) return m.traits.stepping == Stepping::fixed;
        else if constexpr (std::is_same_v<A, FictitiousSteps>) return is_time_transformed(m);
        else if constexpr (std::is_same_v<A, ControlledSteps>) return is_step_controlled(m);
        else return false;
      },
      how);
  if (ok) return;
  if (std::holds_alternative<Accuracy>(how))
    throw Error("the accuracy mode chooses its own step: its run of " + m.name + " takes " + takes);
  throw Error(m.name + " takes " + takes + ", not the way of advancing time given");
}

double steps_landing_on(double t_end, double h_max) { return std::max(1.0, std::ceil(t_end / h_max * (1.0 - 1e-12))); }

void detail::stop_on_request() { throw StoppedOnRequest(); }

namespace {

/// A run by step asks for at most this many steps (1e13 steps of the cheapest method take days).
constexpr double kMostSteps = 1e13;

Error too_many_steps(double t_end, double h) {
  return Error("the end time / the step h (" + detail::short_number(t_end) + " / " + detail::short_number(h) +
               ") asks for more than 1e13 steps");
}

}  // namespace

FixedSteps fixed_steps_to(double t_end, double h_max) {
  require_positive(h_max, "the step h");
  require_positive(t_end, "the end time t_end");
  const double n = steps_landing_on(t_end, h_max);
  if (!(n <= kMostSteps)) throw too_many_steps(t_end, h_max);
  const auto steps = static_cast<long>(n);
  return {t_end / n, steps};
}

FixedSteps thesis_code_steps(double h, long steps, double t_end) {
  require_positive(h, "the step h");
  double n = static_cast<double>(steps);
  if (t_end > 0.0) {
    require_positive(t_end, "the end time t_end");
    n = std::trunc(t_end / h);
  }
  if (!(n <= kMostSteps))
    throw t_end > 0.0 ? too_many_steps(t_end, h) : Error("the number of steps " + detail::short_number(n) + " is above 1e13");
  if (n < 2.0)
    throw Error("the thesis's code takes n - 1 steps of n asked (n = " + detail::short_number(n) + "): no step; ask for n >= 2");
  return {h, static_cast<long>(n) - 1};
}

std::string_view outcome_name(Outcome o) {
  switch (o) {
    case Outcome::ok: return "ok";
    case Outcome::diverged: return "diverged";
    case Outcome::collision: return "collision";
    case Outcome::refused: return "refused";
    case Outcome::failed: return "failed";
    case Outcome::unresolved: return "unresolved";
    case Outcome::inaccurate: return "inaccurate";
    case Outcome::incomplete: return "incomplete";
  }
  return "?";
}

RunResult run(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres, const Advance& how,
              const RunOptions& options) {
  validate(Scene{centres, {body}});
  check(how);
  check_takes(method, how);
  check(options);
  if (const std::string why = refusal(method, body, centres); !why.empty()) throw Error(why);
  return method.run(body, centres, how, options);
}

}  // namespace bodypoint
