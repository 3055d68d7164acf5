// bodypoint: the time-transformed (logh-*, ttl-*) and regularised (ks) methods, run by one driver
// (FictitiousLoop) that each of them plugs a Stepper into.
//
// A run takes fixed fictitious steps ds (FictitiousSteps). Run to an end time, it stops at exactly t_end:
// the fictitious step that would pass t_end is undone, and the last step ds' in (0, ds) is solved
// so that the physical time it advances is the remaining time (the advance grows monotonically with
// ds'; a safeguarded secant iteration, a few steps). The last step is thus a step of the same scheme,
// which keeps its properties (for logH on a material point: the exact Kepler orbit). Otherwise it
// takes the number of fictitious steps asked for. With a sink and dt_out > 0, states at t = k dt_out are
// made by side steps from the state before the crossing step (one step of the same table in physical
// time; for ks the exact advance), without touching the main integration.
#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/accuracy.hpp"

#include "bodypoint/adaptive/extrapolated.hpp"
#include "bodypoint/adaptive/ks.hpp"
#include "bodypoint/adaptive/landing.hpp"
#include "bodypoint/adaptive/time_transformed.hpp"
#include "bodypoint/detail/run_support.hpp"
#include "bodypoint/splitting/catalogue.hpp"
#include "bodypoint/detail/run_parts.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

namespace bodypoint::adaptive {
namespace {

namespace sp = splitting;
using detail::dispatch;
using detail::observe;

/// A run to t_end that needs more fictitious steps than this is stopped with an error.
constexpr long kMaxFictitiousSteps = 2'000'000'000L;

/// Checked every kProgressCheck fictitious steps: the run would need this many more times its budget
/// of steps at the rate it advances physical time (logH at --h 1e-300 ran 18 minutes into the cap).
constexpr long kProgressCheck = 1L << 20;

/// Physical time must advance with every fictitious step (a time transformation that breaks down,
/// e.g. TTL with D ~ 1e-12, turns it backwards), and at a rate that reaches t_end within `cap` steps.
void check_progress(long steps, double t_prev, double t, double t_end, long cap) {
  if (!(t > t_prev))
    throw Error("physical time stopped advancing at t = " + detail::short_number(t_prev) + " (step dt = " +
                detail::short_number(t - t_prev) + "): the time transformation broke down; reduce the fictitious step ds or check D = m J - B^2");
  if (t_end > 0.0 && steps > 0 && steps % kProgressCheck == 0) {
    const double needed = static_cast<double>(steps) * t_end / t;
    if (needed > static_cast<double>(cap))
      throw Error("at its rate so far (t = " + detail::short_number(t) + " after " + std::to_string(steps) +
                  " fictitious steps) the run needs about " + detail::short_number(needed) +
                  " steps to reach t_end, more than the budget of 2e9; increase the fictitious step ds");
  }
}

using detail::StepStats;

/// From `from` (whose time is below target), the state at exactly `target`: a fictitious step ds'
/// with advance(ds') = target - from.time(), where the whole step ds reaches t_full >= target (known
/// to the caller, which has just taken it). Regula falsi with Illinois safeguard on [0, ds], starting
/// from the linear interpolant; stops when the remaining gap is below 4 ulp of the target. The advance
/// is close to linear in ds', so this takes 2-3 trial steps per output time.
/// `group`: the step is taken as that many of ds / group (FictitiousSteps::group).
template <const auto& Seq, class K>
TimeState step_to_time(K& k, const TimeState& from, double ds, double target, double t_full, int group = 1) {
  splitting::NullObserver none;
  const double f_lo = from.time() - target, f_hi = t_full - target;
  TimeState x = from;
  const double tol = 4.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(target));
  if (std::abs(f_hi) <= tol) {  // the whole step lands on the target
    sp::integrate<Seq>(k, x, ds / group, group, none);
    return x;
  }
  land_step(
      [&](double s) {
        x = from;
        sp::integrate<Seq>(k, x, s / group, group, none);
        return x.time() - target;
      },
      0.0, f_lo, ds, f_hi, tol);
  return x;
}

/// The one driver of every method that takes fixed fictitious steps ds: a number of them, or as many
/// as reach an end time, the last one solved to land on it exactly. A Stepper holds the
/// kernel and says, for its state type X:
///   StepAdvance step(X& x, double ds)       one fictitious step; returns the new time and the physical step
///   double time(const X& x)             the physical time of x
///   void land(X& x, double t, double t_over)  from x (time < t) to exactly t; t_over is where a whole
///                                             step would have gone
///   State at(const X& prev, double t)   the physical state at t in (time(prev), next step's time]
///   State physical(const X& x)
///   std::string_view prefix             of its error messages ("" or "ks: ")
/// Outputs at k dt_out come from at() on the state before the step that crosses them.
struct StepAdvance {
  double t;   ///< physical time after the step
  double dt;  ///< physical step, as the step statistics record it
};

template <class Stepper>
class FictitiousLoop {
 public:
  using X = typename Stepper::X;

  FictitiousLoop(Stepper& s, const FictitiousSteps& spec) : s_(s), spec_(spec), next_out_(spec.dt_out) {}

  /// Runs from x; returns the final state and leaves the statistics in stats(). The loop keeps its
  /// step, end time and statistics in locals (members read through `this` every step cost 3-8%).
  template <class Obs>
  X run(X x, Obs& obs) {
    const bool to_time = spec_.t_end() > 0.0;
    const long cap = to_time ? kMaxFictitiousSteps : spec_.steps();
    const double h = spec_.ds, t_end = spec_.t_end();
    StepStats st;
    double t_over = 0.0;  // the time the step that would pass t_end reaches
    bool goes_on = true;  // false once the observer ended the run (its sink said Flow::stop)
    while (st.steps < cap) {
      const X prev = x;
      const StepAdvance a = s_.step(x, h);
      if (!std::isfinite(a.t) || !s_.physical_finite(x))
        throw Error(std::string(Stepper::prefix) + "the state became non-finite at t = " +
                    std::to_string(s_.time(prev)) + "; reduce the fictitious step ds");
      check_progress(st.steps, s_.time(prev), a.t, t_end, cap);
      if (to_time && a.t >= t_end) {
        x = prev;
        t_over = a.t;
        break;
      }
      st.add(a.dt);
      if constexpr (Obs::active) {
        outputs_until(obs, prev, a.t, st.steps);
        obs.observe(st.steps, a.t, x, !to_time && st.steps == cap);
      }
      if (!(goes_on = splitting::poll(obs, st.steps))) break;
    }
    if (to_time && goes_on) finish(x, t_over, cap, obs, st);
    st_ = st;
    return x;
  }

  const StepStats& stats() const { return st_; }

 private:
  /// The last step, solved to land on t_end, and the outputs up to it.
  template <class Obs>
  void finish(X& x, double t_over, long cap, Obs& obs, StepStats& st) {
    if (st.steps >= cap) throw Error("more than 2e9 fictitious steps before t_end; increase the fictitious step ds");
    const X prev = x;
    const double t_end = spec_.t_end(), rest = t_end - s_.time(x);
    if (rest > 0.0) {
      s_.land(x, t_end, t_over);
      st.add(rest);
    }
    s_.set_time(x, t_end);
    if constexpr (Obs::active) {
      // Output times before t_end from the step before it; t_end itself is the landed state.
      outputs_until(obs, prev, t_end, st.steps, true);
      obs.observe(st.steps, t_end, x, true);
      if (obs.wants_times()) obs.emit(st.steps, t_end, s_.physical(x));
    }
  }

  /// States at the requested output times in (time(prev), t_upto] (`before`: in (time(prev), t_upto));
  /// output times are n dt_out, not a running sum.
  template <class Obs>
  void outputs_until(Obs& obs, const X& prev, double t_upto, long steps, bool before = false) {
    if (!obs.wants_times()) return;
    while (before ? next_out_ < t_upto : next_out_ <= t_upto) {
      obs.emit(steps, next_out_, s_.at(prev, next_out_));
      next_out_ = static_cast<double>(++n_out_) * spec_.dt_out;
    }
  }

  Stepper& s_;
  const FictitiousSteps& spec_;
  StepStats st_;
  long n_out_ = 1;
  double next_out_;
};

/// Runs a Stepper through FictitiousLoop with the observer the options ask for (invariants, samples).
template <class Stepper, class Field>
RunResult run_fictitious(Stepper& s, typename Stepper::X x0, const Body& body, const Field& field,
                         const FictitiousSteps& spec, const RunOptions& options) {
  using X = typename Stepper::X;
  FictitiousLoop<Stepper> loop(s, spec);
  double t_reached = 0.0, carried = std::numeric_limits<double>::quiet_NaN();
  auto to_physical = [&s](const X& x) { return s.physical(x); };
  RunResult r = observe(body.p, field, body.s0, options, detail::grid_of(spec), to_physical, [&](auto& obs) {
    const X x = loop.run(x0, obs);
    t_reached = s.time(x);
    if constexpr (requires { s.carried(x); }) carried = s.carried(x);
    return s.physical(x);
  });
  loop.stats().record(r, t_reached);
  if (!r.stopped) r.carried = carried;  // a sink's stop: the final state is not the loop's
  return r;
}

/// logH and TTL kernels as a Stepper: the table's steps in fictitious time, the last one solved for
/// its length (step_to_time), dense output by one step of the same table in physical time.
template <class K, const auto& Seq>
struct TransformedStepper {
  using X = TimeState;
  static constexpr std::string_view prefix = "";
  K& k;
  double h;
  int group = 1;  ///< FictitiousSteps::group: a step of ds is this many of ds / group
  StepAdvance step(X& x, double ds) const {
    const double before = x.time();
    sp::NullObserver none;
    sp::integrate<Seq>(k, x, ds / group, group, none);
    return {x.time(), x.time() - before};
  }
  static double time(const X& x) { return x.time(); }
  bool physical_finite(const X& x) const { return x.q.R.allFinite(); }
  void land(X& x, double t, double t_over) const { x = step_to_time<Seq>(k, x, h, t, t_over, group); }
  static void set_time(X& x, double t) {
    x.t = t;
    x.t_err = 0.0;
  }
  // Dense output: one step of the same table in physical time from prev over the gap, which is at
  // most the physical step just taken, so its local error is no larger. Solving for the fictitious
  // step that lands on the output time took 4.1 trial steps per output; this takes one, at the same
  // accuracy (logh-kl8, close scene, ds = 0.08, dt-out = 1: max error 3.33e-11 both ways against
  // ds = 0.01; dt-out = 0.1: 19,414 force evaluations instead of 61,455).
  State at(const X& prev, double t) const {
    splitting::LieState q = prev.q;
    sp::NullObserver none;
    sp::integrate<Seq>(k.lp, q, t - prev.time(), 1, none);
    return k.lp.to_physical(q);
  }
  State physical(const X& x) const { return k.to_physical(x); }
  static double carried(const X& x) { return K::carried(x); }
};

template <template <class, bool> class Kernel, const auto& Seq>
RunResult run_time_transformed(const Body& body, const std::vector<Centre>& centres, const Advance& how,
                               const RunOptions& options) {
  const auto& spec = std::get<FictitiousSteps>(how);
  return dispatch(body, centres, [&](const auto& field, auto spin) {
    using K = Kernel<std::decay_t<decltype(field)>, decltype(spin)::value>;
    K k(body.p, field, options.omega_c >= 0.0 ? options.omega_c : automatic_omega_c(body, centres, spec.ds));
    TransformedStepper<K, Seq> stepper{k, spec.ds, spec.group};
    TimeState x0 = k.initial_state(body.s0);
    if (!std::isnan(options.carried)) K::resume(x0, options.carried);
    RunResult r = run_fictitious(stepper, x0, body, field, spec, options);
    r.steps *= spec.group;  // the steps taken, each group's every one
    r.force_evals = k.lp.evals;
    return r;
  });
}

// What each time-transformed family assumes of a scene (MethodInfo::check).
std::string coulomb_only(const MethodInfo& m, const std::vector<Centre>& centres) {
  if (!non_coulomb(centres)) return "";
  return m.name + " assumes Coulomb's law (its time transformation is built on -A/|R|); the thesis "
         "code's force law runs with the fixed-step, Runge-Kutta and step-size-controlled methods";
}
std::string logh_check(const MethodInfo& m, const Body& /*body*/, const std::vector<Centre>& centres) {
  if (std::string why = coulomb_only(m, centres); !why.empty()) return why;
  if (!all_repulsive(centres))
    return "logh-* needs every centre repulsive (A < 0) so that Pi > 0; use ttl-* (any sign of A) or ks (material "
           "point, one centre)";
  return "";
}
std::string ttl_check(const MethodInfo& m, const Body& /*body*/, const std::vector<Centre>& centres) {
  if (std::string why = coulomb_only(m, centres); !why.empty()) return why;
  double total = 0.0;
  for (const Centre& c : centres) total += std::abs(c.A);
  if (!(total > 0.0)) return "ttl-* needs a centre with A != 0 (its time step function is sum |A|/r)";
  return "";
}
std::string ks_check(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres) {
  if (std::string why = coulomb_only(m, centres); !why.empty()) return why;
  if (body.p.B != 0.0) return "ks regularises a material point: it needs B = 0 (use logh-* or ttl-*)";
  if (centres.size() != 1) return "ks needs exactly one centre (use logh-* or ttl-*)";
  return "";
}

/// The Kustaanheimo-Stiefel motion as a Stepper: exact in fictitious time, so the last step and the
/// outputs are exact advances in physical time. The physical time is summed compensated (Kahan), as the
/// time-transformed kernels' (TimeState): a plain sum loses a rounding of t per step (ks, ds = 0.01 on a
/// bound orbit to t = 300, 16,806 steps: 1.1e-12 off the Kepler orbit summed plainly, 1.5e-13 compensated).
struct KsStepper {
  struct X {
    KsMotion motion;
    double t = 0.0;
    double t_err = 0.0;  ///< what the sum t has not taken in (t - t_err is the time)
  };
  static constexpr std::string_view prefix = "ks: ";
  static StepAdvance step(X& x, double ds) {
    const double dt = x.motion.step(ds);
    splitting::compensated_add(x.t, x.t_err, dt);
    return {time(x), dt};
  }
  static double time(const X& x) { return x.t - x.t_err; }
  static bool physical_finite(const X& x) { return x.motion.state().R.allFinite(); }
  static void land(X& x, double t, double) { x.motion.advance_time(t - time(x)); }
  static void set_time(X& x, double t) {
    x.t = t;
    x.t_err = 0.0;
  }
  static State at(const X& prev, double t) {
    KsMotion side = prev.motion;
    if (t > time(prev)) side.advance_time(t - time(prev));
    return side.state();
  }
  static State physical(const X& x) { return x.motion.state(); }
};

RunResult run_ks(const Body& body, const std::vector<Centre>& centres, const Advance& how, const RunOptions& options) {
  CentreList field{centres};  // for the invariants (K2Q about c)
  KsStepper stepper;
  RunResult r = run_fictitious(stepper, KsStepper::X{KsMotion(body.p, centres.front(), body.s0)}, body, field,
                               std::get<FictitiousSteps>(how), options);
  r.force_evals = 0;  // the regularised flow is exact: no force evaluations
  return r;
}

/// The row of a time-transformed method: kernel family K (logH or TTL) times the entry's table.
template <template <class, bool> class K, class E>
MethodInfo transformed_row(std::string_view prefix, std::string_view family, SceneCheck check) {
  using T = typename E::type;
  const int s = static_cast<int>(sp::ops_of<T>.kicks());
  MethodInfo m{std::string(prefix) + std::string(E::tag), Family::TimeTransformed, T::order, s, s,
               sp::describe<T>(family), &run_time_transformed<K, sp::ops_of<T>>, check};
  m.table = E::tag;
  m.symmetric = sp::ops_of<T>.symmetric();
  return m;
}

}  // namespace

std::vector<MethodInfo> methods() {
  std::vector<MethodInfo> all;
  sp::for_each(sp::TimeTransformedTables{}, [&all]<class E>() {
    all.push_back(transformed_row<LogHKernel, E>("logh-", "logH (repulsive scenes), fictitious step ds", &logh_check));
  });
  sp::for_each(sp::TimeTransformedTables{}, [&all]<class E>() {
    all.push_back(transformed_row<TtlKernel, E>("ttl-", "TTL (any sign of A), fictitious step ds", &ttl_check));
  });
  all.push_back({"ks", Family::Regularised, 0, 0, 0,
                 "Kustaanheimo-Stiefel regularisation, exact in fictitious time (B = 0, one centre), fictitious step ds",
                 &run_ks, &ks_check});
  all.push_back({"logh-bs", Family::Extrapolated, 0, 0, 0,
                 "logH leapfrog with Bulirsch-Stoer extrapolation (Mikkola's codes; repulsive scenes); a tolerance per step",
                 &run_logh_bs, &logh_bs_check});
  for (MethodInfo& m : all) m.traits = catalogue_traits(m.family);
  return all;
}

}  // namespace bodypoint::adaptive
