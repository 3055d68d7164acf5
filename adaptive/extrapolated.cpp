// bodypoint: logh-bs, the logarithmic-Hamiltonian leapfrog with Bulirsch-Stoer extrapolation and a
// tolerance per step, the time-transformed peer that Mikkola's regularised codes are built on
// (S. Mikkola, S. J. Aarseth, "A time-transformed leapfrog scheme", Celest. Mech. Dyn. Astron. 84
// (2002) 343, sec. 4; S. Mikkola, K. Tanikawa, "Algorithmic regularization of the few-body problem",
// MNRAS 310 (1999) 745).
//
// A macro step H in the fictitious time s is the logH leapfrog (drift H/2n, then n - 1 times kick H/n
// and drift H/n, kick H/n, drift H/2n; the kernel of logh-*, time_transformed.hpp, with c = 0) taken
// with n = 2, 4, 6, ... substeps. The leapfrog is time-symmetric, so its error expands in even powers
// of H/n, and the results are extrapolated to H/n = 0 by Aitken-Neville in (H/n)^2 (Gragg, Bulirsch
// and Stoer; E. Hairer, S. P. Norsett, G. Wanner, Solving Ordinary Differential Equations I, 2nd ed.,
// Springer 1993, sec. II.9). The difference of the last two diagonal entries estimates the error of
// the extrapolated state (R, K1, K2, t and the logH variable g = E - T), measured component-wise
// against tol (1 + |y|) as GSL's and Boost.Odeint's standard controls do. Order and step follow the
// work per unit step (ibid., the ODEX strategy, simplified): the step is accepted at the first column
// that meets tol, rejected (H divided) when the last allowed one does not. The last step is solved
// so that it ends at t_end exactly (a secant on H; t grows monotonically with H).
//
// The extrapolated state is not a Poisson map: |K2|^2 and K2Q are kept to the tolerance, not to
// round-off. Scenes: every centre repulsive (logH needs Pi > 0), Coulomb's law.
#include "bodypoint/adaptive/extrapolated.hpp"

#include "bodypoint/adaptive/landing.hpp"
#include "bodypoint/adaptive/time_transformed.hpp"
#include "bodypoint/detail/run_support.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

namespace bodypoint::adaptive {
namespace {

using detail::dispatch;
using detail::observe;

/// Columns of the extrapolation table: substeps n_j = 2 j, j = 1..kMaxColumns (Deuflhard's sequence).
constexpr int kMaxColumns = 9;
/// The first order target (columns) of a run.
constexpr int kStartColumns = 4;
/// Step-size factor bounds and safety (Hairer-Norsett-Wanner's ODEX defaults, sec. II.9).
constexpr double kSafety = 0.94, kSafetyOrder = 0.65, kMinFactor = 0.02, kMaxFactor = 4.0;
/// Rejections in a row before the run stops with the reason.
constexpr int kMaxRejections = 60;

/// The extrapolated variables: R, K1, K2, t, g.
using Vec = std::array<double, 11>;

Vec pack(const TimeState& x) {
  const Vec3 R = x.q.R - x.q.R_err, K1 = x.q.K1 - x.q.K1_err;
  return {R.x(), R.y(), R.z(), K1.x(), K1.y(), K1.z(), x.q.K2.x(), x.q.K2.y(), x.q.K2.z(), x.time(), x.g};
}

/// `like` with its variables replaced by v (its |K2|^2 reference kept for the drift's rotation).
TimeState unpack(const Vec& v, const TimeState& like) {
  TimeState x = like;
  x.q.R = Vec3(v[0], v[1], v[2]);
  x.q.K1 = Vec3(v[3], v[4], v[5]);
  x.q.K2 = Vec3(v[6], v[7], v[8]);
  x.q.R_err.setZero();
  x.q.K1_err.setZero();
  x.t = v[9];
  x.t_err = 0.0;
  x.g = v[10];
  return x;
}

constexpr int substeps(int j) { return 2 * j; }  // j = 1, 2, ...

/// Force evaluations of a macro step that computes columns 1..j.
constexpr double work_of(int j) { return static_cast<double>(j * (j + 1)); }

template <class K>
struct Extrapolator {
  K& k;
  double tol;

  /// The logH leapfrog over H with n substeps from x; not finite when a substep is too long for the
  /// encounter (a kick that makes E - T <= 0: the macro step is rejected, not the run).
  Vec leapfrog(const TimeState& x0, double H, int n) const {
    TimeState x = x0;
    const double h = H / n;
    auto drift = [&](double ds) {
      if (!(x.g + k.c > 0.0)) return false;
      k.drift(x, ds);
      return true;
    };
    bool ok = drift(0.5 * h);
    for (int i = 1; ok && i < n; ++i) {
      k.kick(x, h);
      ok = drift(h);
    }
    if (ok) {
      k.kick(x, h);
      ok = drift(0.5 * h);
    }
    if (!ok) {
      Vec bad;
      bad.fill(std::numeric_limits<double>::quiet_NaN());
      return bad;
    }
    return pack(x);
  }

  /// The scaled error of the difference a - b: max_i |a_i - b_i| / (tol (1 + |a_i|)).
  double error(const Vec& a, const Vec& b) const {
    double e = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      const double x = std::abs(a[i] - b[i]) / (tol * (1.0 + std::abs(a[i])));
      if (!std::isfinite(x)) return std::numeric_limits<double>::infinity();  // a rejected leapfrog
      e = std::max(e, x);
    }
    return e;
  }

  struct Attempt {
    Vec y{};
    int columns = 0;  ///< the column the step was accepted at (0: rejected)
    double err = std::numeric_limits<double>::infinity();
    std::array<double, kMaxColumns + 1> factor{};  ///< the step factor each column's error asks for
  };

  /// One macro step from x0 with columns up to `most`, accepted at the first column >= `least` whose
  /// error meets tol (all columns computed when `least` = `most` = fixed and tol is ignored: landing).
  Attempt step(const TimeState& x0, double H, int least, int most, bool fixed = false) const {
    std::array<Vec, kMaxColumns + 1> T{};  // T[k] the row's entry of column k (Neville's scheme, in place)
    Attempt a;
    for (int j = 1; j <= most; ++j) {
      Vec row = leapfrog(x0, H, substeps(j));
      // Aitken-Neville: T_{j,k} = T_{j,k-1} + (T_{j,k-1} - T_{j-1,k-1}) / ((n_j / n_{j-k+1})^2 - 1).
      Vec prev_diag{};
      for (int c = 1; c < j; ++c) {
        const double ratio = static_cast<double>(substeps(j)) / substeps(j - c);
        const double den = ratio * ratio - 1.0;
        Vec next{};
        for (std::size_t i = 0; i < row.size(); ++i) next[i] = row[i] + (row[i] - T[c][i]) / den;
        T[c] = row;
        if (c == j - 1) prev_diag = row;
        row = next;
      }
      T[j] = row;
      if (j == 1) continue;
      const double err = error(row, prev_diag);
      a.factor[j] = std::clamp(kSafety * std::pow(kSafetyOrder / std::max(err, 1e-300), 1.0 / (2 * j - 1)),
                               kMinFactor, kMaxFactor);
      if (fixed ? j == most : (j >= least && err <= 1.0)) {
        a.y = row;
        a.columns = j;
        a.err = err;
        return a;
      }
      a.err = err;
    }
    return a;
  }
};

/// How the controlled-step driver words this peer's failures.
std::string stalled(double t) {
  return "logh-bs: the macro step collapsed at t = " + detail::short_number(t) +
         " (the tolerance is below what double precision resolves, or the body fell onto a centre)";
}

/// The macro step from x that ends at exactly t_end: a secant (regula falsi, Illinois) on its length
/// in (0, H], the whole step H reaching t_over > t_end, at the column count the step was accepted with.
template <class K>
TimeState land(const Extrapolator<K>& ex, const TimeState& x, double H, int columns, double t_over, double t_end) {
  const double t0 = x.time();
  const double f_lo = t0 - t_end, f_hi = t_over - t_end;
  const double tol = 4.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t_end));
  TimeState y = x;
  land_step(
      [&](double s) {
        y = unpack(ex.step(x, s, columns, columns, true).y, x);
        return y.time() - t_end;
      },
      0.0, f_lo, H, f_hi, tol);
  y.t = t_end;
  y.t_err = 0.0;
  return y;
}

template <class K, class Obs>
TimeState run_macro_steps(K& k, TimeState x, const ControlledSteps& spec, Obs& obs, detail::StepStats& st) {
  const Extrapolator<K> ex{k, spec.tol};
  // The first fictitious step from the first physical one: dt = ds / g at the start.
  double H = spec.h0 * x.g;
  int target = kStartColumns;
  int rejected = 0;
  long macro = 0;
  while (x.time() < spec.t_end) {
    if (++macro > detail::kMaxAdaptiveSteps) throw Error("logh-bs: more than 2e8 macro steps before t_end; loosen the tolerance");
    if (!splitting::poll(obs, macro)) break;  // a cancellation is seen between rejected steps too
    const auto a = ex.step(x, H, std::max(2, target - 1), std::min(kMaxColumns, target + 1));
    if (a.columns == 0) {  // rejected at every column allowed
      if (++rejected > kMaxRejections || !(H > 0.0)) throw Error(stalled(x.time()));
      H *= std::min(0.5, a.factor[std::min(kMaxColumns, target + 1)]);
      continue;
    }
    TimeState y = unpack(a.y, x);
    if (!std::isfinite(y.time()) || !y.q.R.allFinite()) throw Error(stalled(x.time()));
    if (!(y.time() > x.time())) throw Error(stalled(x.time()));
    if (y.time() > spec.t_end) y = land(ex, x, H, a.columns, y.time(), spec.t_end);
    rejected = 0;
    const double dt = y.time() - x.time();
    x = y;
    st.add(dt);
    detail::check_adaptive_rate(st.steps, x.time(), spec.t_end);  // a rate that cannot reach t_end stops the run
    if constexpr (Obs::active) obs.observe(st.steps, x.time(), pack(x), x.time() >= spec.t_end);
    // Order and step by the work per unit step (force evaluations over the step each column's error
    // allows): one column fewer when that is cheaper, one more when the accepted one was cheaper than
    // the one below it, else the same.
    const int j = a.columns;
    const double w_j = work_of(j) / a.factor[j];
    const double w_below = j > 2 ? work_of(j - 1) / a.factor[j - 1] : std::numeric_limits<double>::infinity();
    if (w_below < 0.9 * w_j) {
      target = j - 1;
      H *= a.factor[j - 1];
    } else if (j + 1 < kMaxColumns && w_j < 0.9 * w_below) {
      target = j + 1;
      H *= a.factor[j] * work_of(j + 1) / work_of(j);
    } else {
      target = j;
      H *= a.factor[j];
    }
  }
  return x;
}

}  // namespace

std::string logh_bs_check(const MethodInfo& m, const Body& /*body*/, const std::vector<Centre>& centres) {
  if (non_coulomb(centres))
    return m.name + " assumes Coulomb's law (its time transformation is built on -A/|R|)";
  if (!all_repulsive(centres))
    return m.name + " needs every centre repulsive (A < 0) so that Pi > 0; use a ttl-* method or a Runge-Kutta peer";
  return "";
}

RunResult run_logh_bs(const Body& body, const std::vector<Centre>& centres, const Advance& how,
                      const RunOptions& options) {
  const auto& spec = std::get<ControlledSteps>(how);
  return dispatch(body, centres, [&](const auto& field, auto spin) {
    using K = LogHKernel<std::decay_t<decltype(field)>, decltype(spin)::value>;
    K k(body.p, field, 0.0);  // pure logH: the extrapolation's control sets the step
    const TimeState x0 = k.initial_state(body.s0);
    detail::StepStats st;
    auto to_physical = [&](const Vec& v) { return k.to_physical(unpack(v, x0)); };
    RunResult r = observe(body.p, field, body.s0, options, detail::grid_of(spec), to_physical, [&](auto& obs) {
      return k.to_physical(run_macro_steps(k, x0, spec, obs, st));
    });
    r.force_evals = k.lp.evals;
    st.record(r, spec.t_end);
    return r;
  });
}

}  // namespace bodypoint::adaptive
