// bodypoint: the step search behind --tol (tolerance.hpp).
//
// The search, for a method of order p, in as few integrations as the scene allows. Runs that share
// one time-step constant c (time-transformed methods; a pair compared by Richardson must be one
// method) form a ladder, coarse to fine; each new run's error is estimated from the run before it,
// est = |x_a - x_b|/((h_a/h_b)^p - 1), and the estimate is trusted when the error behaves like C h^p
// there: the three last runs fit an order between p - kOrderSlack and p + kOrderExcess, or (a ladder of
// two) the estimate is what the coarser runs predicted for it, within kAgree.
// 1. Pilot pair: runs at a coarse step h0 (a fictitious step that advances the orbit by about one
//    radian per step at closest approach, or a fixed step of one spin-orbit period) and h0/2, with the
//    c of h0. A run the method refuses (logH's E - T + c <= 0, a non-finite state) halves h0.
// 2. The latest estimate predicts the step h* that gives kTarget tol. When h*'s own c is well below
//    the ladder's (far from the centres a run costs ~c/ds steps per unit time), a new ladder starts:
//    the answer at h* and its companion at kCompanionRatio h* (half the cost of the answer). Otherwise
//    the answer at h* joins the ladder, whose finest run is its companion: one run.
// 3. A trusted estimate at most kAccept tol delivers the answer; otherwise back to 2.
// The delivered run is the one that carries the observers (invariants, samples): samples go to a buffer
// handed to the caller's sink only when its run is delivered, so nothing is integrated twice.
// Differences that stop shrinking far below 1 are round-off: the search reports the floor it met
// (what the finest runs still differ by).
#include "bodypoint/adaptive/tolerance.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/adaptive/richardson.hpp"
#include "bodypoint/field.hpp"
#include "bodypoint/invariants.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

namespace bodypoint::adaptive {
namespace {

/// The predicted step aims at this fraction of tol: the error of a step predicted from a coarser
/// pair is uncertain by a factor of a few (the local order differs from p before the asymptotic
/// range), and a prediction that misses costs one more run.
constexpr double kTarget = 0.3;
/// A run is delivered when its estimated error is at most this fraction of tol.
constexpr double kAccept = 0.8;
/// The answer's companion runs at this multiple of its step: it costs 1/kCompanionRatio of the
/// answer. A larger ratio costs less but makes the estimate depend more on the local order q of the
/// error (it is off by (r^q - 1)/(r^p - 1): 4x for q = p + 2 at r = 2).
constexpr double kCompanionRatio = 2.0;
/// A triple whose observed order is this much below p is not smooth in h there.
constexpr double kOrderSlack = 1.0;
/// A triple whose observed order is more than this above p is not in the asymptotic range either: its
/// middle run may sit where the error passes through zero (three centres at 1e-7, ttl-kl6: relative errors
/// 3.5e-5 / 5.5e-8 / 1.8e-8 at ds = 0.31 / 0.15 / 0.095, an order of 9.3 over the triple and an estimate
/// 8x below the error), or its coarsest run converge faster than h^p (lp-kl6 on far passes: estimates up
/// to 500x above the error; an encounter at 1e-10, b = 1: delivered 7.2e-10 off with an estimate of 1.1e-11).
/// Such a triple is trusted where the one before it showed the same (a scattering run's end converges faster
/// than h^p throughout). docs/developers.md, "The observed order's upper bound".
constexpr double kOrderExcess = 2.0;
/// Orders above this are not told apart (the fit's bracket).
constexpr double kMaxOrder = 40.0;
/// A new run's estimate agrees with the one the coarser runs predicted for it within this factor.
constexpr double kAgree = 10.0;
/// A new ladder (answer and companion, 1 + 1/kCompanionRatio runs) is started for a predicted step
/// whose own constant c is below this fraction of the ladder's: far from the centres a run costs
/// about c/ds steps per unit time, so the new ladder's answer costs at most this fraction of a run
/// at that step on the old ladder, and the pair less than that one run.
constexpr double kNewConstantGain = 0.5;
/// A repeated prediction is at least this much finer than the run it failed with.
constexpr double kMinRefinement = 1.25;
/// The search gives up after this many refinements in a row that did not lower its error estimate
/// by kStallFactor (scene long at tol 1e-12 spent 2e9 force evaluations, about 100 s, before).
constexpr int kMaxStalls = 3;
constexpr double kStallFactor = 2.0;
/// Estimates that stop falling are a floor (round-off amplified by an encounter: 4e-12 on B = 0.9, b = 1)
/// where the runs differ by less than kStallBelow: kMaxStalls refinements in a row end the search. Above
/// it the step is still outside the asymptotic regime, where refinement lowers them (lp-kl8 at tol 1e-3
/// on a two-centre pass stalled at runs 1.1e-3 apart; at 1e-4 it is delivered): kMaxFarStalls halvings
/// are allowed.
constexpr double kStallBelow = 1e-8;
constexpr int kMaxFarStalls = 8;
/// Budget of force evaluations (or KS steps) over all runs of one search.
constexpr double kMaxEvals = 2e9;
/// Below kProbeBelowTol (tolerance.hpp) a run about to be delivered is repeated kProbeRuns times: all but
/// one with its roundings changed (the step moved by a relative k kProbeShift, or k fixed steps more: the
/// truncation error moves by far less than tol), one from its start moved by kStartShift. An encounter amplifies round-off: on B = 0.9, b = 1 runs differ by
/// ~4e-12 whatever the step, and a pair at the answer's step and twice it can agree with C h^p by
/// chance (estimate 1.9e-14 for a true error of 3.8e-12 at tol 1e-13). Richardson cannot tell that
/// floor from truncation; runs that differ only in rounding measure it. One such pair is a random draw
/// of the floor: with one, and the estimate the larger of truncation and floor, 3 of the 256 scenes of
/// `bench/estimate_grid.py --tols 1e-12` missed it (up to 2.2e-12); with the larger of two, measured
/// on each run about to be delivered, and the estimate their sum (both errors are in the delivered run),
/// none did, for 24 refusals instead of 18 and 28 % more force evaluations. (kProbeShift: tolerance.hpp.)
/// far-ip's pair (exact_flow) starts its finer run from the start moved by this relative amount: one unit
/// in the last place, the rounding the start's conversion to momenta makes; its third run's start moves by
/// kStartShift the other way.
constexpr double kFarStartShift = std::numeric_limits<double>::epsilon();
/// With the round-off floor known, the next step aims its truncation error at what the floor leaves of
/// tol, but at no less than this share of tol (a floor near kAccept tol would ask for a step of zero).
constexpr double kMinAimShare = 0.1;
/// far-ip's first step turns the spin by at most this many turns: its force evaluations per unit time are
/// nearly flat in the step beyond a turn, while each point's share of the step's dense quadrature grows with
/// the points (far pass d = 50 of table 3.1: h = 1, 6.9 rad, 4,320 evaluations in 1.7 ms; h = 6.67, 3,968
/// in 5.2 ms).
constexpr double kFarFieldTurns = 1.0;
/// Runs that differ by more than this relative amount (more than the state itself) follow no common
/// trajectory: their difference predicts no step (Richardson assumes the error ~ C h^p). Pairs 10-100 %
/// apart still predict well (logh-y4 on the close pass at 1e-4: with 0.1 here, one more run, 4.3x the
/// delivered run instead of 3.5x).
constexpr double kUnresolvedPair = 1.0;
/// Refinements before the search gives up.
constexpr int kMaxLevels = 48;
/// Differences at or below this relative size are at the round-off level of a run of 1e3..1e6 steps.
constexpr double kRoundOff = 1e-13;

/// A limit of the search itself (its budget, the smallest step it takes): final, unlike a method's
/// refusal of one step, which only halves the pilot's step.
struct SearchLimit : Error {
  using Error::Error;
};

/// The samples a run that may be delivered keeps for the caller's sink, at most (112 bytes each: 117 MB).
/// Beyond, they are dropped and the delivered run is made again with the sink (the same steps, the same
/// bits): a scattering run to its departure under events at tol 1e-10 (B = 0.9, b = 1) kept every step
/// of its finest rungs and reached 24 GB before the kernel killed it.
constexpr std::size_t kMaxKeptSamples = std::size_t{1} << 20;

struct Level {
  double h = 0.0;
  long steps = 0;
  double omega_c = 0.0;
  RunResult run;
  std::vector<KeptSample> samples;  ///< kept until the run is known to be the delivered one
  bool samples_dropped = false;     ///< more than kMaxKeptSamples: the delivery runs it again
  Advance how;                      ///< what it ran, for that run again
};

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

/// The way of advancing time at step h: fictitious steps ds = h to t_end for time-transformed methods,
/// otherwise the fixed steps of at most h that land on t_end (fixed_steps_to's rule).
Advance step_advance(const MethodInfo& m, double h, double t_end, double dt_out) {
  if (is_time_transformed(m)) return FictitiousSteps{h, EndTime{t_end}, dt_out};
  const double n = steps_landing_on(t_end, h);
  if (!(n <= 1e12)) throw SearchLimit("tol: the step the search needs (" + std::to_string(h) + ") is too small");
  return FixedSteps{t_end / n, static_cast<long>(n), dt_out};
}

/// The first, coarse step of the ladder.
double initial_step(const MethodInfo& m, const Body& b, const std::vector<Centre>& centres, double t_end) {
  if (m.traits.search == SearchStrategy::exact_pair) {
    // KS fictitious time: one sub-step of the exact flow (sqrt(2 |h|) ds = 1, ks.hpp).
    const double mu = centres.front().A / b.p.m;
    const double h = 0.5 * b.s0.v.squaredNorm() - mu / (b.s0.R - centres.front().c).norm();
    return h != 0.0 ? 1.0 / std::sqrt(2.0 * std::abs(h)) : 1.0;
  }
  if (m.traits.search == SearchStrategy::field_pair) {
    // far-ip's step is set by the field's slow scale (far_field.hpp): the time the guiding centre takes to
    // cover its least distance to the nearest centre; a step too long for the field is refused and halved.
    const Helix helix = helix_of(b.p, to_momenta(b.p, b.s0));
    double r = std::numeric_limits<double>::infinity();
    for (const Centre& c : centres) r = std::min(r, path_distance(helix, c.c, t_end));
    const double v = helix.velocity.norm(), turn = spin_orbit_period(b);
    return std::min({t_end, v > 0.0 ? r / v : t_end, kFarFieldTurns * turn});
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
  Search(const MethodInfo& m, const Body& b, const std::vector<Centre>& c, const Accuracy& a,
         const RunOptions& delivery, bool verify)
      : m_(m), b_(b), c_(c), tol_(a.tol), t_end_(a.t_end), dt_out_(a.dt_out), p_(effective_order(m, b)),
        delivery_(delivery), verify_(verify) {}

  ToleranceResult search() {
    Level best = p_ > 0 ? ladder() : exact_flow();
    ToleranceResult out;
    out.h = best.h;
    out.steps = best.steps;
    out.omega_c = best.omega_c;
    out.err_estimate = estimate_;
    out.basis = (p_ > 0                                ? std::string("Richardson over its runs")
                 : m_.traits.search == SearchStrategy::field_pair ? "what " + pair_text() + " differ by"
                                                 : "what runs at fictitious steps ds and ds/" + fmt_number(kMinRefinement) +
                                                       " differ by: the KS flow is exact") +
                (floor_ > 0.0 ? ", plus runs that differ only in rounding" : "");
    out.result = std::move(best.run);
    out.runs = runs_;
    out.total_force_evals = total_evals_;
    out.total_wall_s = total_wall_;
    // The delivered run is over: a sink's Flow::stop ends its samples, not the run.
    if (delivery_.sink && best.samples_dropped) {
      replay(best);
      out.total_force_evals = total_evals_;
      out.total_wall_s = total_wall_;
    } else if (delivery_.sink) {
      for (const KeptSample& k : best.samples)
        if ((*delivery_.sink)(k.sample()) == Flow::stop) break;
    }
    return out;
  }

 private:
  /// Runs the method at step h (ds for time-transformed methods; a fixed step is rounded to t_end/n)
  /// with the time-step constant that the step h_c calls for (time-transformed methods; a pair of
  /// runs compared by Richardson must share it to be one method). A run that may be delivered
  /// carries the observers the caller asked for, its samples kept aside.
  Level run_at(double h, double h_c, bool may_deliver, const Body* from = nullptr) {
    const bool samples = may_deliver && delivery_.sink;
    const Advance how = step_advance(m_, h, t_end_, samples ? dt_out_ : 0.0);
    RunOptions o = run_options(automatic_omega_c(b_, c_, h_c), may_deliver);
    Level l;
    SampleSink keep;
    if (may_deliver) {
      if (samples) {
        keep = [&l](const Sample& x) {
          if (l.samples_dropped) return;
          if (l.samples.size() < kMaxKeptSamples) return l.samples.push_back(KeptSample::of(x));
          l.samples = {};
          l.samples_dropped = true;
        };
        o.sink = &keep;
      }
    }
    const double expected = expected_evals(how);
    if (spent_evals_ + expected > kMaxEvals)
      throw SearchLimit("tol " + fmt_tol() + " is out of reach of " + std::string(m_.name) +
                        " within 2e9 force evaluations (last estimate " + fmt_number(last_estimate_) + ")");
    // The scene, the request and the method's acceptance of the scene were checked once; each step
    // the search makes is valid by construction, and the method runs without run()'s checks.
    l.run = m_.run(from ? *from : b_, c_, how, o);
    if (!(l.run.final.R.allFinite() && l.run.final.v.allFinite())) throw Error("the state became non-finite");
    if (const auto* fixed = std::get_if<FixedSteps>(&how)) {
      l.h = fixed->h;
      l.steps = fixed->steps;
    } else {
      l.h = h;
    }
    l.omega_c = o.omega_c;
    l.how = how;
    spent_evals_ += static_cast<double>(std::max(l.run.force_evals, l.run.steps));
    total_wall_ += l.run.wall_s;
    total_evals_ += l.run.force_evals;
    ++runs_;
    return l;
  }

  /// The options of a search's run with constant c omega_c: the caller's cancel, and where it may be
  /// delivered, the caller's observers (invariants, every k-th step; its sink is the caller's to attach).
  RunOptions run_options(double omega_c, bool may_deliver) const {
    RunOptions o;
    o.omega_c = omega_c;
    o.cancel = delivery_.cancel;
    o.track_invariants = may_deliver && delivery_.track_invariants;
    if (may_deliver) o.every = delivery_.every;
    return o;
  }

  /// The delivered run made again with the caller's sink, where it had more samples than were kept: the
  /// same steps and constant c give the same states; the sink's Flow::stop ends its samples, not the run.
  void replay(const Level& best) {
    RunOptions o = run_options(best.omega_c, true);
    bool ended = false;
    SampleSink forward = [&](const Sample& x) {
      if (!ended && (*delivery_.sink)(x) == Flow::stop) ended = true;
    };
    o.sink = &forward;
    const RunResult again = m_.run(b_, c_, best.how, o);
    total_evals_ += again.force_evals;
    total_wall_ += again.wall_s;
    ++runs_;
  }

  /// The pilot pair at h0 and h0/2 (a refused step halves h0); sets the first estimate and returns
  /// the finer run (never delivered: an estimate from the pilot pair alone was
  /// off by 25x on two-centres at 1e-4, docs/developers.md, "Limits, measured").
  Level pilot(Level& coarse) {
    double h = initial_step(m_, b_, c_, t_end_);
    for (int k = 0;; ++k) {
      try {
        coarse = run_at(h, h, false);
        Level fine = run_at(0.5 * coarse.h, h, false);
        // A pair that differs by more than kUnresolvedPair is no trajectory yet (rk4 at h = 0.91 and 0.45
        // on table 3.1: 2.9e25 apart, whose Richardson prediction was a step of 1.4e-8 and a refusal for
        // the budget): the pair moves down by halvings, each run one more at half the step (their sum at
        // most the last pair's cost), with the same constant c, until it differs by less.
        for (int d = 0; state_distance(coarse.run.final, fine.run.final) > kUnresolvedPair && d < kMaxLevels; ++d) {
          coarse = std::move(fine);
          fine = run_at(0.5 * coarse.h, h, false);
        }
        estimate_ = pair_estimate(coarse, fine);
        return fine;
      } catch (const SearchLimit&) {
        throw;
      } catch (const StoppedOnRequest&) {
        throw;
      } catch (const Error&) {
        if (k >= kMaxLevels) throw;
        h *= 0.5;
      }
    }
  }

  /// Order-p methods (file comment): runs that share one time-step constant c form a ladder; each new
  /// run is estimated from the run before it (Richardson, order p) and checked by the run before that.
  Level ladder() {
    std::vector<Level> rungs;  // runs sharing the constant c of step h_c, coarse to fine
    Level coarse;
    Level fine = pilot(coarse);
    double h_c = coarse.h;
    rungs.push_back(std::move(coarse));
    rungs.push_back(std::move(fine));
    double best_bound = std::numeric_limits<double>::infinity();
    int stalled = 0;
    bool verified_finer = false;  // the newest rung is a verification's companion: estimate it first
    for (int k = 0; k < kMaxLevels; ++k) {
      const double expected = verified_finer ? estimate_ * std::pow(0.5, p_) : refine(rungs, h_c);
      verified_finer = false;
      Level& a = rungs[rungs.size() - 2];
      const Level& b = rungs.back();
      a.samples = {};  // only the newest run can still be delivered: its predecessors' samples go
      estimate_ = pair_estimate(a, b);
      last_estimate_ = estimate_;
      const double d = state_distance(a.run.final, b.run.final);
      if (d <= kRoundOff && estimate_ > kAccept * tol_)
        throw Error("tol " + fmt_tol() + " is below the round-off floor of " + std::string(m_.name) +
                    " on this scene (estimate " + fmt_number(estimate_) + ")");
      // The estimate is trusted when the error behaves like C h^p: the three last runs of the ladder
      // show an order within [p - kOrderSlack, p + kOrderExcess], or (two runs) the estimate is what the model
      // carried over from the coarser runs predicted, within kAgree.
      bool smooth = estimate_ <= kAgree * expected && estimate_ >= expected / kAgree;
      if (rungs.size() >= 3) {
        // An order far above p is trusted where the triple before showed it too: a scattering run's final
        // state converges faster than h^p throughout (the error at the end of an encounter is that of a
        // processed method), where one run sitting at a zero of the error shows it once.
        const std::size_t n = rungs.size();
        const double q = observed_order(rungs[n - 3], a, b);
        const bool again = n >= 4 && observed_order(rungs[n - 4], rungs[n - 3], a) > p_ + kOrderExcess;
        smooth = q >= p_ - kOrderSlack && (q <= p_ + kOrderExcess || again);
      }
      if (deliverable(rungs.back(), h_c, smooth || d <= kRoundOff)) {
        if (verified(rungs, h_c)) return std::move(rungs.back());
        verified_finer = true;  // its companion joined the ladder
        continue;
      }
      // A search whose estimates stop falling (round-off, or resonances that refinement does not
      // remove) says so instead of spending its whole budget; larger differences are not a floor but a
      // step still outside the asymptotic regime (kStallBelow).
      if (estimate_ < best_bound / kStallFactor) {
        best_bound = estimate_;
        stalled = 0;
      } else if (++stalled < (d > kStallBelow ? kMaxFarStalls : kMaxStalls)) {
        continue;
      } else if (d <= tol_) {
        // The finest runs differ by less than tol but their estimates are not trusted (not smooth in h):
        // what they differ by bounds the finer one's error once its own companion agrees (kep-kl6 on a
        // material close pass was refused at every tol with runs 4.98e-12 apart). A refusal never
        // quotes a difference below the tol asked (logh-kl6 at 1e-9: "still differ by 9.39e-10").
        if (verified_at(rungs, h_c, d)) return std::move(rungs.back());
        verified_finer = true;
        stalled = 0;
      } else {
        // The floor is what finer runs still disagree by, not the smallest estimate: an early pair
        // can agree by chance (B = 0.9, b = 1 at tol 1e-12: first estimate 9.9e-15, then three
        // refinements each 4e-12 apart, which one of them must be wrong by half of).
        throw Error("tol " + fmt_tol() + " is out of reach of " + std::string(m_.name) +
                    " on this scene: runs at finer steps still differ by " + fmt_number(d) +
                    " (round-off amplified by the scene, or resonances that refinement does not remove)");
      }
    }
    throw Error("tol " + fmt_tol() + ": " + std::string(m_.name) + " did not reach it in " +
                std::to_string(kMaxLevels) + " refinements");
  }

  /// Adds the ladder's next run, at the step the estimate predicts for what TOL leaves to truncation;
  /// far finer than the ladder so far, it starts a new ladder (h_c changes). Returns the error the
  /// model C h^p expects of the new run.
  double refine(std::vector<Level>& rungs, double& h_c) {
    // Once a round-off floor was measured (below kProbeBelowTol), the truncation aims at what it leaves.
    const double aim = kTarget * std::max(tol_ - std::max(floor_, 0.0) / kAccept, kMinAimShare * tol_);
    const double predicted = rungs.back().h * std::pow(aim / std::max(estimate_, kRoundOff), 1.0 / p_);
    if (automatic_omega_c(b_, c_, kCompanionRatio * predicted) < kNewConstantGain * rungs.back().omega_c) {
      // Far finer than the ladder so far: a new ladder whose constant c is that of the companion's
      // step, so that the answer does not pay for the coarse runs' larger c in the far field.
      h_c = kCompanionRatio * predicted;
      rungs.clear();
      rungs.push_back(run_at(h_c, h_c, false));
      rungs.push_back(run_at(predicted, h_c, true));
      return kTarget * tol_;
    }
    const double h = std::min(predicted, rungs.back().h / kMinRefinement);
    const double expected = estimate_ * std::pow(h / rungs.back().h, p_);
    rungs.push_back(run_at(h, h_c, true));
    return expected;
  }

  /// Whether the newest run `l` may be delivered: its estimate (and the round-off floor measured so far)
  /// within TOL, and the estimate `trusted`. Below kProbeBelowTol the round-off is probed on `l` itself
  /// and added to the estimate; round-off alone above TOL throws.
  bool deliverable(const Level& l, double h_c, bool trusted) {
    if (!(estimate_ + std::max(floor_, 0.0) <= kAccept * tol_ && trusted)) return false;
    if (tol_ >= kProbeBelowTol) return true;
    // Measured on the run that may be delivered: a floor measured on another run is another draw
    // of the round-off (reused from a coarser run, 2 of 256 scenes at tol 1e-12 missed it).
    floor_ = rounding_floor(l, h_c);
    if (floor_ > kAccept * tol_)
      throw Error("tol " + fmt_tol() + " is out of reach of " + std::string(m_.name) +
                  " on this scene: runs that differ only in rounding differ by " + fmt_number(floor_) +
                  " (round-off amplified by the scene)");
    // Truncation and round-off add up in the delivered run: its estimate is their sum. Where the
    // sum is above what may be delivered, a finer run lowers the truncation part.
    if (estimate_ + floor_ > kAccept * tol_) return false;
    estimate_ = last_estimate_ = estimate_ + floor_;
    return true;
  }

  /// Whether the ladder's newest run may be delivered as it is: without verification (auto: its choices'
  /// estimates were measured honest), or when its companion at half its step, run now, agrees within TOL
  /// (its difference over 1 - 2^-p: the error of the run at h). A companion that does not agree joins the
  /// ladder as its newest run (false): the search goes on from there.
  bool verified(std::vector<Level>& rungs, double h_c) {
    return !verify_ || verified_at(rungs, h_c, estimate_);
  }
  /// The same with the delivered run's estimate `current`, which the companion's can only raise.
  bool verified_at(std::vector<Level>& rungs, double h_c, double current) {
    Level half = run_at(0.5 * rungs.back().h, h_c, true);
    const double e = coarser_run_error(state_distance(rungs.back().run.final, half.run.final), 2.0, p_);
    if (e + std::max(floor_, 0.0) <= kAccept * tol_) {
      estimate_ = last_estimate_ = std::max(current, e + std::max(floor_, 0.0));
      return true;
    }
    rungs.back().samples = {};
    rungs.push_back(std::move(half));
    return false;
  }

  /// The most that the run `l` and its kProbeRuns repeats with other roundings differ by (kProbeBelowTol):
  /// a repeat moves a fictitious step by k kProbeShift, or takes k fixed steps more; the last runs from the
  /// starting state moved by a rounding (kStartShift relative, in R and v). Repeats from one start share
  /// what the scene makes of the start's own rounding: on a near head-on pass (kep-y4 at tol 1e-12) the
  /// runs at N, N+1 and N+2 steps differed by 3.4e-13 and were all 1.75e-11 from a binary128 reference,
  /// whose start is the exact one; the moved start shows that amplification.
  double rounding_floor(const Level& l, double h_c) {
    double floor = 0.0;
    for (int k = 1; k < kProbeRuns; ++k) {
      const double h = is_time_transformed(m_) ? l.h * (1.0 - k * kProbeShift)
                                               : t_end_ / static_cast<double>(l.steps + k);
      floor = std::max(floor, state_distance(l.run.final, run_at(h, h_c, false).run.final));
    }
    const Body moved = start_moved(kStartShift);
    return std::max(floor, state_distance(l.run.final, run_at(l.h, h_c, false, &moved).run.final));
  }

  /// The body with its start moved by a relative `shift`: R scaled by 1 + shift, v by 1 - shift.
  [[nodiscard]] Body start_moved(double shift) const {
    Body moved = b_;
    moved.s0.R *= 1.0 + shift;
    moved.s0.v *= 1.0 - shift;
    return moved;
  }

  /// The order q with which x(h) = x* + C h^q fits three runs at steps h1 > h2 > h3: the root of
  /// (h1^q - h2^q)/(h2^q - h3^q) = d12/d23 (increasing in q), by bisection on [0, kMaxOrder].
  static double observed_order(const Level& l1, const Level& l2, const Level& l3) {
    const double d12 = state_distance(l1.run.final, l2.run.final), d23 = state_distance(l2.run.final, l3.run.final);
    if (!(d23 > 0.0)) return kMaxOrder;
    const double target = d12 / d23;
    auto ratio = [&](double q) {
      const double a = std::pow(l1.h / l3.h, q), b = std::pow(l2.h / l3.h, q);
      return (a - b) / (b - 1.0);
    };
    double lo = 1e-3, hi = kMaxOrder;
    if (ratio(lo) >= target) return 0.0;
    if (ratio(hi) <= target) return kMaxOrder;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (ratio(mid) < target ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }

  /// Richardson's estimate of the finer run's error from a pair at steps h_c > h_f, order p.
  [[nodiscard]] double pair_estimate(const Level& c, const Level& f) const {
    return finer_run_error(state_distance(c.run.final, f.run.final), c.h / f.h, p_);
  }

  /// Methods without an order p (ks: exact in fictitious time; far-ip: spectral in its step, its error
  /// the iteration's, the alias's and the rounding's, far_field.hpp): two runs at steps h and h/kMinRefinement
  /// bound the error by what they differ by. far-ip's error is mostly the scene's amplified rounding, which
  /// one pair draws once: its second run starts from the start moved by kFarStartShift, and a third run at
  /// h from the start moved the other way by kStartShift; the estimate is the larger difference (with the
  /// pair alone 47 of 768 estimates of bench/estimate_grid.py were more than 3x below the error, the worst
  /// 30x; with the third run 2 of 256 at TOL 1e-7, the worst 6x, for 3.2x the delivered run's evaluations
  /// instead of 2.2x). Below kProbeBelowTol the third run gives way to the ladder's rounding probe, added to
  /// the pair's difference. An estimate above what tol allows halves the step (a step too coarse for the
  /// field errs more), until kMaxStalls halvings in a row did not halve it: the floor it met. A step the
  /// method refuses (far-ip: its iteration does not converge there) is halved too.
  Level exact_flow() {
    double h = initial_step(m_, b_, c_, t_end_);
    const bool far = m_.traits.search == SearchStrategy::field_pair;
    const Body moved = start_moved(kFarStartShift), rounded = start_moved(-kStartShift);
    double best = std::numeric_limits<double>::infinity();
    int stalled = 0;
    for (int k = 0;; ++k) {
      try {
        Level a = run_at(h, h, true);
        const Level b = run_at(h / kMinRefinement, h, false, far ? &moved : nullptr);
        estimate_ = std::max(state_distance(a.run.final, b.run.final), std::numeric_limits<double>::epsilon());
        if (far && tol_ >= kProbeBelowTol) {
          estimate_ = std::max(estimate_, state_distance(a.run.final, run_at(h, h, false, &rounded).run.final));
        } else if (far) {
          // Below kProbeBelowTol the ladder's rounding probe (kProbeRuns draws) is added, as for the
          // ladder's answer: at 1e-13 on a swing round an attracting centre, after 5 halvings the pair and
          // the one moved start agreed to 4.8e-14 for an error of 2.2e-13.
          floor_ = rounding_floor(a, h);
          estimate_ += floor_;
        }
        last_estimate_ = estimate_;
        if (estimate_ <= kAccept * tol_) return a;
        if (estimate_ < best / kStallFactor) {
          best = estimate_;
          stalled = 0;
        } else {
          best = std::min(best, estimate_);
          ++stalled;
        }
        if (!far || k >= kMaxLevels || stalled >= kMaxStalls)
          throw SearchLimit("tol " + fmt_tol() + " is below what " + std::string(m_.name) + " delivers on this scene: " +
                            (far ? "the estimate from " + pair_text() + " was at least " : "runs differ by ") +
                            fmt_number(best) + (far ? " at every step it tried" : ""));
      } catch (const SearchLimit&) {
        throw;
      } catch (const StoppedOnRequest&) {
        throw;
      } catch (const Error&) {
        if (!far || k >= kMaxLevels) throw;
      }
      h *= 0.5;
    }
  }

  [[nodiscard]] double expected_evals(const Advance& how) const {
    if (const auto* fixed = std::get_if<FixedSteps>(&how))
      return static_cast<double>(fixed->steps) * std::max(1, m_.evals_per_step);
    return 0.0;  // unknown in advance; the budget is checked against what was spent
  }
  [[nodiscard]] std::string fmt_tol() const { return fmt_number(tol_); }
  /// far-ip's runs (exact_flow), as its estimate's basis and its refusal name them.
  static std::string pair_text() {
    return "runs at steps h and h/" + fmt_number(kMinRefinement) + " and from starts moved by a rounding";
  }
  static std::string fmt_number(double x) {
    std::ostringstream os;
    os.precision(3);
    os << x;
    return os.str();
  }

  const MethodInfo& m_;
  const Body& b_;
  const std::vector<Centre>& c_;
  double tol_, t_end_, dt_out_;
  int p_;
  RunOptions delivery_;
  bool verify_;  ///< a run about to be delivered is checked against a companion at half its step
  double estimate_ = 0.0, last_estimate_ = std::numeric_limits<double>::quiet_NaN();
  double floor_ = -1.0;  ///< the round-off floor last measured (below kProbeBelowTol), -1 before
  double spent_evals_ = 0.0, total_wall_ = 0.0;
  long total_evals_ = 0;
  int runs_ = 0;
};

}  // namespace

int effective_order(const MethodInfo& m, const Body& b) {
  // The thesis's schemes freeze the gyroscopic term: first order for B != 0 (README, findings).
  if (m.traits.frozen_gyroscopic_term && b.p.B != 0.0) return 1;
  return m.order;
}

double state_distance(const State& a, const State& b) {
  auto rel = [](const Vec3& x, const Vec3& y) {
    const double n = y.norm();
    return n > 0.0 ? (x - y).norm() / n : (x - y).norm();
  };
  return std::max(rel(a.R, b.R), rel(a.v, b.v));
}

void check_tolerance(double tol) {
  require_positive(tol, "the tolerance tol");
  if (tol < kMinTolerance)
    throw Error("tol below 1e-13 cannot be delivered in double precision (the round-off of a run is "
                "1e-15..1e-13 relative)");
  if (!(tol < 1.0)) throw Error("tol must be below 1 (it is a relative error of the final state)");
}

void check_searchable(const MethodInfo& method) {
  if (is_step_controlled(method))
    throw Error(std::string(method.name) + " controls its own step: give it a tolerance per step, not the accuracy mode's "
                "search (which is for fixed-step and time-transformed methods)");
  if (method.traits.search == SearchStrategy::none || (method.traits.search == SearchStrategy::ladder && method.order == 0))
    throw Error(std::string(method.name) + " has no fixed order for the error estimate");
}

ToleranceResult run_to_tolerance(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres,
                                 const Accuracy& accuracy, const RunOptions& delivery, bool verify) {
  check_tolerance(accuracy.tol);
  check(Advance(accuracy));
  check(delivery);
  check_searchable(method);
  validate(Scene{centres, {body}});
  if (non_coulomb(centres)) throw Error(std::string(kNeedsCoulomb));
  if (const std::string why = refusal(method, body, centres); !why.empty()) throw Error(why);
  return search_step(method, body, centres, accuracy, delivery, verify);
}

ToleranceResult search_step(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres,
                            const Accuracy& accuracy, const RunOptions& delivery, bool verify) {
  return Search(method, body, centres, accuracy, delivery, verify).search();
}

}  // namespace bodypoint::adaptive
