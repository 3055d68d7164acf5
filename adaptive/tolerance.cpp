// bodypoint: the step search behind --tol (tolerance.hpp).
//
// The search, for a method of order p:
// 1. Two runs at a coarse h0 (a fictitious step that advances the orbit by about one radian per step
//    at closest approach, or a fixed step of one spin-orbit period) and h0/2. A run the method
//    refuses (logH's E - T + c <= 0, a non-finite state) only halves the step.
// 2. The pair's Richardson estimate est = |x_a - x_b|/((h_a/h_b)^p - 1) predicts the step h* that
//    would give kTarget tol (at least kMinRefinement finer than the pilot).
// 3. Runs at r^2 h*, r h* and h* (r = kCloseRatio, all with the time-step constant c of r^2 h*) give
//    two estimates of the error of x(h*): from the pair (r h*, h*), and from (r^2 h*, r h*) scaled by
//    r^-p. If they agree within kSmoothBand (the error is smooth in h there) and the larger is at most
//    kAccept tol, x(h*) is delivered with the first as its estimate. Otherwise step 2 predicts again
//    (or, when the two disagree, h* is refined by kMinRefinement).
// Differences that stop shrinking far below 1 are round-off: the finest run is delivered when they are
// below kAccept tol, otherwise the search reports the floor it met.
#include "bodypoint/adaptive/tolerance.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/field.hpp"
#include "bodypoint/invariants.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace bodypoint::adaptive {
namespace {

/// The predicted step aims at this fraction of tol, so that the estimate, itself uncertain by a
/// factor of a few before the asymptotic regime is deep, still lands below tol.
constexpr double kTarget = 0.2;
/// A run is delivered when its estimated error is at most this fraction of tol.
constexpr double kAccept = 0.5;
/// The error of the delivered run is estimated from a second run at a step this much coarser. A ratio
/// close to 1 makes the estimate insensitive to the local order q of the error, which differs from the
/// nominal p before the asymptotic range (optimised 8th-order tables fall like h^13..h^25 there):
/// d = err (r^q - 1), and the estimate d/(r^p - 1) is off by (r^q - 1)/(r^p - 1), 2.8x for q = 2p,
/// 0.7x for q = 3p/4 at r = 1.1, where a ratio of 2 would be off by 250x for p = 8, q = 16.
constexpr double kCloseRatio = 1.1;
/// A repeated prediction is at least this much finer than the run it failed with.
constexpr double kMinRefinement = 1.5;
/// The delivered run's error is estimated twice, from the pairs (r^2 h, r h) and (r h, h) with the
/// first scaled by r^-p; an error that is smooth in h gives two estimates within this factor. Rough
/// errors were measured on long runs where the far-field step meets spin-orbit resonances (scene
/// long, logh-kl8: 9.8e-8 at ds = 0.082, 1.8e-7 at 0.075, 3.0e-9 at 0.068): there a single pair
/// underestimated the error 50x.
constexpr double kSmoothBand = 3.0;
/// The search gives up after this many refinements in a row that did not lower its error estimate
/// by kStallFactor (scene long at tol 1e-12 spent 2e9 force evaluations, about 100 s, before).
constexpr int kMaxStalls = 3;
constexpr double kStallFactor = 2.0;
/// The observed order of a triple is trusted up to this multiple of the nominal order.
constexpr double kMaxOrderFactor = 2.0;
/// Budget of force evaluations (or KS steps) over all runs of one search.
constexpr double kMaxEvals = 2e9;
/// Refinements before the search gives up.
constexpr int kMaxLevels = 48;
/// Differences at or below this relative size are at the round-off level of a run of 1e3..1e6 steps.
constexpr double kRoundOff = 1e-13;

/// A limit of the search itself (its budget, the smallest step it takes): final, unlike a method's
/// refusal of one step, which only halves the pilot's step.
struct SearchLimit : Error {
  using Error::Error;
};

struct Level {
  double h = 0.0;
  long steps = 0;
  State final;
  long evals = 0;
  double wall = 0.0;
  double omega_c = 0.0;
};

int effective_order(const MethodInfo& m, const Body& b) {
  // The thesis's schemes freeze the gyroscopic term: first order for B != 0 (README, findings).
  if (m.family == Family::Thesis && b.p.B != 0.0) return 1;
  return m.order;
}

double speed_of(const Body& b) { return b.s0.v.norm(); }

double strength(const std::vector<Centre>& centres) {
  double s = 0.0;
  for (const Centre& c : centres) s += std::abs(c.A);
  return s;
}

double spin_orbit_period(const Body& b) {
  const double rate = std::abs(b.p.B) * to_momenta(b.p, b.s0).K1.norm() / b.p.D();
  return rate > 0.0 ? 2.0 * M_PI / rate : std::numeric_limits<double>::infinity();
}

/// base with the step h: ds and t_end for time-transformed methods, otherwise n = ceil(t_end/h)
/// steps of t_end/n.
RunSpec step_spec(const MethodInfo& m, double h, double t_end, RunSpec s) {
  if (is_time_transformed(m)) {
    s.h = h;
    s.steps = 0;
    s.t_end = t_end;
    return s;
  }
  const double n = std::ceil(t_end / h * (1.0 - 1e-12));
  if (!(n <= 1e12)) throw SearchLimit("tol: the step the search needs (" + std::to_string(h) + ") is too small");
  s.steps = std::max(1L, static_cast<long>(n));
  s.h = t_end / static_cast<double>(s.steps);
  s.t_end = 0.0;
  return s;
}

/// The first, coarse step of the ladder.
double initial_step(const MethodInfo& m, const Body& b, const std::vector<Centre>& centres, double t_end) {
  if (m.family == Family::Regularised) {
    // KS fictitious time: one sub-step of the exact flow (sqrt(2 |h|) ds = 1, ks.hpp).
    const double mu = centres.front().A / b.p.m;
    const double h = 0.5 * b.s0.v.squaredNorm() - mu / (b.s0.R - centres.front().c).norm();
    return h != 0.0 ? 1.0 / std::sqrt(2.0 * std::abs(h)) : 1.0;
  }
  if (is_time_transformed(m)) {
    // dt = ds r/|A| near a centre advances the orbit by ds v/|A| radians: one radian per step.
    const double v = speed_of(b), a = strength(centres);
    return (v > 0.0 && a > 0.0) ? a / v : 0.1;
  }
  return std::min(t_end / 16.0, spin_orbit_period(b));
}

class Search {
 public:
  Search(const MethodInfo& m, const Body& b, const std::vector<Centre>& c, double tol, double t_end)
      : m_(m), b_(b), c_(c), tol_(tol), t_end_(t_end), p_(effective_order(m, b)) {}

  /// Runs the method at step h (ds for time-transformed methods; a fixed step is rounded to t_end/n).
  /// Runs at step h with the time-step constant that the step h_c calls for (time-transformed
  /// methods; a pair of runs compared by Richardson must share it to be one method).
  Level run_at(double h, double h_c) {
    RunSpec s = step_spec(m_, h, t_end_, RunSpec{});
    s.omega_c = automatic_omega_c(b_, c_, h_c);
    const double expected = expected_evals(s);
    if (spent_evals_ + expected > kMaxEvals)
      throw SearchLimit("tol " + fmt_tol() + " is out of reach of " + std::string(m_.name) +
                  " within 2e9 force evaluations (last estimate " + fmt_number(last_estimate_) + ")");
    // The scene and the method's acceptance of it were checked once (run_to_tolerance); each run's
    // specification is checked here, and the method runs without run()'s checks of the scene.
    (void)advance_of(m_, s);
    const RunResult r = m_.run(b_, c_, s, nullptr);
    if (!(r.final.R.allFinite() && r.final.v.allFinite())) throw Error("the state became non-finite");
    Level l{s.h, s.steps, r.final, std::max(r.force_evals, r.steps), r.wall_s, s.omega_c};
    spent_evals_ += static_cast<double>(l.evals);
    total_wall_ += r.wall_s;
    total_evals_ += r.force_evals;
    ++runs_;
    return l;
  }

  ToleranceResult search() {
    const Level best = p_ > 0 ? ladder() : exact_flow();
    ToleranceResult out;
    out.h = best.h;
    out.steps = best.steps;
    out.omega_c = best.omega_c;
    out.err_estimate = estimate_;
    out.result.final = best.final;
    out.result.steps = best.steps;
    out.result.t_end = t_end_;
    out.result.force_evals = best.evals;
    out.result.wall_s = best.wall;
    out.runs = runs_;
    out.total_force_evals = total_evals_;
    out.total_wall_s = total_wall_;
    return out;
  }

 private:
  /// The pilot pair at h0 and h0/2 (a refused step halves h0); sets the first estimate and returns
  /// the finer run.
  Level pilot() {
    double h = initial_step(m_, b_, c_, t_end_);
    Level a, b;
    for (int k = 0;; ++k) {
      try {
        a = run_at(h, h);
        b = run_at(0.5 * a.h, h);
        break;
      } catch (const SearchLimit&) {
        throw;
      } catch (const Error&) {
        if (k >= kMaxLevels) throw;
        h *= 0.5;
      }
    }
    estimate_ = pair_estimate(a, b);
    return b;
  }

  /// Order-p methods: pilot pair, predicted step, close pair (file comment).
  Level ladder() {
    // 1. The pilot pair, coarse and cheap.
    const Level b = pilot();
    // 2./3. Predict, estimate from a close triple, repeat until the estimate is below kAccept tol.
    Level fine = b;
    double h_next = 0.0, best_bound = std::numeric_limits<double>::infinity();
    int stalled = 0;
    for (int k = 0; k < kMaxLevels; ++k) {
      const double predicted = fine.h * std::pow(kTarget * tol_ / std::max(estimate_, kRoundOff), 1.0 / p_);
      const double h_star = k == 0 || h_next == 0.0 ? std::min(predicted, fine.h / kMinRefinement) : h_next;
      const double r = kCloseRatio, h_c = h_star * r * r;  // the triple shares the constant c of its coarsest step
      const Level coarsest = run_at(h_c, h_c);
      const Level coarse = run_at(h_star * r, h_c);
      fine = run_at(h_star, h_c);
      const double e_fine = pair_estimate(coarse, fine);
      const double e_mid = pair_estimate(coarsest, coarse) * std::pow(fine.h / coarse.h, p_);
      // Where the error falls faster than h^p (before the asymptotic range), the observed order q of
      // the triple, d(r^2 h, r h)/d(r h, h) = r^q, gives the better estimate (Roache's generalised
      // Richardson extrapolation); it is used only up to kMaxOrderFactor p, and never below p.
      const double d_mid = state_distance(coarsest.final, coarse.final);
      const double d_fine = state_distance(coarse.final, fine.final);
      const double q_obs = d_fine > 0.0 ? std::log(d_mid / d_fine) / std::log(coarse.h / fine.h) : p_;
      const double q = std::clamp(std::isfinite(q_obs) ? q_obs : p_, double(p_), kMaxOrderFactor * p_);
      estimate_ = d_fine / (std::pow(coarse.h / fine.h, q) - 1.0);
      last_estimate_ = estimate_;
      const double bound = std::max(e_fine, e_mid);
      const bool smooth = bound <= kSmoothBand * std::min(e_fine, e_mid) || q_obs >= p_;
      if (state_distance(coarse.final, fine.final) <= kRoundOff && bound > kAccept * tol_)
        throw Error("tol " + fmt_tol() + " is below the round-off floor of " + std::string(m_.name) +
                    " on this scene (estimate " + fmt_number(estimate_) + ")");
      if (bound <= kAccept * tol_ && (smooth || bound <= kRoundOff)) return fine;
      // Not accurate enough: predict again; not smooth in h (a resonance of the far-field step with the
      // spin-orbit precession): refine by kMinRefinement, which also lowers the spin angle per step.
      h_next = smooth ? 0.0 : fine.h / kMinRefinement;
      // A search whose estimates stop falling (round-off, or resonances that refinement does not
      // remove) says so instead of spending its whole budget.
      if (bound < best_bound / kStallFactor) {
        best_bound = bound;
        stalled = 0;
      } else if (++stalled >= kMaxStalls) {
        throw Error("tol " + fmt_tol() + " is out of reach of " + std::string(m_.name) +
                    " on this scene: the error estimate stalls at " + fmt_number(best_bound));
      }
    }
    throw Error("tol " + fmt_tol() + ": " + std::string(m_.name) + " did not reach it in " +
                std::to_string(kMaxLevels) + " refinements");
  }

  /// Richardson's estimate of the finer run's error from a pair at steps h_c > h_f, order p.
  [[nodiscard]] double pair_estimate(const Level& c, const Level& f) const {
    return state_distance(c.final, f.final) / (std::pow(c.h / f.h, p_) - 1.0);
  }

  /// ks: exact in fictitious time, only rounding and the time equation err; two runs at different
  /// fictitious steps bound that.
  Level exact_flow() {
    const double h = initial_step(m_, b_, c_, t_end_);
    const Level a = run_at(h, h);
    const Level b = run_at(h / kMinRefinement, h);
    estimate_ = std::max(state_distance(a.final, b.final), std::numeric_limits<double>::epsilon());
    if (estimate_ > kAccept * tol_)
      throw Error("tol " + fmt_tol() + " is below what " + std::string(m_.name) + " delivers on this scene (" +
                  fmt_number(estimate_) + ")");
    return a;
  }

  [[nodiscard]] double expected_evals(const RunSpec& s) const {
    if (!is_time_transformed(m_)) return static_cast<double>(s.steps) * std::max(1, m_.evals_per_step);
    return 0.0;  // unknown in advance; the budget is checked against what was spent
  }
  [[nodiscard]] std::string fmt_tol() const { return fmt_number(tol_); }
  static std::string fmt_number(double x) {
    std::ostringstream os;
    os.precision(3);
    os << x;
    return os.str();
  }

  const MethodInfo& m_;
  const Body& b_;
  const std::vector<Centre>& c_;
  double tol_, t_end_;
  int p_;
  double estimate_ = 0.0, last_estimate_ = std::numeric_limits<double>::quiet_NaN();
  double spent_evals_ = 0.0, total_wall_ = 0.0;
  long total_evals_ = 0;
  int runs_ = 0;
};

}  // namespace

double state_distance(const State& a, const State& b) {
  auto rel = [](const Vec3& x, const Vec3& y) {
    const double n = y.norm();
    return n > 0.0 ? (x - y).norm() / n : (x - y).norm();
  };
  return std::max(rel(a.R, b.R), rel(a.v, b.v));
}

void check_tolerance(double tol) {
  if (!std::isfinite(tol) || !(tol > 0.0)) throw Error("tol must be a finite number > 0");
  if (tol < kMinTolerance)
    throw Error("tol below 1e-13 cannot be delivered in double precision (the round-off of a run is "
                "1e-15..1e-13 relative)");
  if (!(tol < 1.0)) throw Error("tol must be below 1 (it is a relative error of the final state)");
}

RunSpec delivered_spec(const MethodInfo& method, const ToleranceResult& r, double t_end, RunSpec base) {
  base.omega_c = r.omega_c;
  return step_spec(method, r.h, t_end, base);
}

ToleranceResult run_to_tolerance(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres,
                                 double tol, double t_end) {
  check_tolerance(tol);
  if (!(std::isfinite(t_end) && t_end > 0.0)) throw Error("the accuracy mode needs an end time t_end that is a finite number > 0");
  if (is_step_controlled(method))
    throw Error(std::string(method.name) + " controls its own step: give it a tolerance per step, not the accuracy mode's "
                "search (which is for fixed-step and time-transformed methods)");
  if (method.order == 0 && method.family != Family::Regularised)
    throw Error(std::string(method.name) + " has no fixed order for the error estimate");
  validate(Scene{centres, {body}});
  if (non_coulomb(centres))
    throw Error(std::string(kNeedsCoulomb));
  if (const std::string why = refusal(method, body, centres); !why.empty()) throw Error(why);
  return Search(method, body, centres, tol, t_end).search();
}

}  // namespace bodypoint::adaptive
