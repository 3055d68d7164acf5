// bodypoint: the search of a method of order p (search.hpp), in as few integrations as the scene allows.
//
// Runs that share one time-step constant c (time-transformed methods; a pair compared by Richardson must be
// one method) form a ladder, coarse to fine; each new run's error is estimated from the run before it,
// est = |x_a - x_b|/((h_a/h_b)^p - 1) (accuracy.hpp), and the estimate is trusted when the error behaves
// like C h^p there: the three last runs fit an order between p - kOrderSlack and p + kOrderExcess, or (a
// ladder of two) the estimate is what the coarser runs predicted for it, within kAgree, and where it reads more
// than kLowPair below that, a third run at twice the companion's step shows the order too (trusted()).
// 1. Pilot pair: runs at a coarse step h0 (start.cpp) and h0/2, with the c of h0. A run the method refuses
//    (logH's E - T + c <= 0, a non-finite state) halves h0. A planned step h* (Accuracy::first_step: a map's
//    plan, from the step its nearest pilot row delivered) replaces the pilot pair by the answer at h* and its
//    companion at kCompanionRatio h*, judged as a new ladder of step 2 is; a planned pair far below its
//    target starts once more from the step it predicts (replanned). Where the pilot pair shows the coarse
//    run within TOL, a run at 2 h0 judges the pair before any finer run (coarser_pilot_answer).
// 2. The latest estimate predicts the step h* that gives kTarget tol. When h*'s own c is well below the
//    ladder's (far from the centres a run costs ~c/ds steps per unit time), a new ladder starts: the answer
//    at h* and its companion at kCompanionRatio h* (half the cost of the answer). Otherwise the answer at
//    h* joins the ladder, whose finest run is its companion: one run. After the first such run the pilot's
//    coarse run is delivered where the two finer runs bound its error within TOL (pilot_answer).
// 3. A trusted estimate at most kAccept tol delivers the answer (with the round-off probe's floor added,
//    rounding.cpp, below kProbeBelowTol or after the ladder's estimates stalled among runs closer than
//    kStallBelow), verified where asked by a companion at h*/kVerifyRatio; otherwise back to 2.
// Differences that stop shrinking far below 1 are round-off: the search reports the floor it met (what the
// finest runs still differ by). Each constant's measurement: docs/measurements.md, "Tuned constants".
#include "search.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace bodypoint::adaptive::detail {
namespace {

/// The predicted step aims at this fraction of tol (tolerance.hpp).
constexpr double kTarget = kTargetShare;
/// The answer's companion runs at this multiple of its step: it costs 1/kCompanionRatio of the answer.
constexpr double kCompanionRatio = 2.0;
/// A triple whose observed order is this much below p is not smooth in h there.
constexpr double kOrderSlack = 1.0;
/// A triple whose observed order is more than this above p is not in the asymptotic range either, unless the
/// triple before it showed the same.
constexpr double kOrderExcess = 2.0;
/// A new run's estimate agrees with the one the coarser runs predicted for it within this factor.
constexpr double kAgree = 10.0;
/// A new ladder's pair whose estimate lies more than this factor below what the coarser runs predicted is
/// judged by a third run too (coarser_rung_confirms): the estimates' honesty factor (the accuracy issue's 3).
constexpr double kLowPair = 3.0;
/// A new ladder is started for a predicted step whose own constant c is below this fraction of the ladder's.
constexpr double kNewConstantGain = 0.5;
/// Estimates that stop falling where the runs differ by less than this are a floor (kMaxStalls refinements in
/// a row end the search); above it the step is still outside the asymptotic regime (kMaxFarStalls allowed).
constexpr double kStallBelow = 1e-8;
constexpr int kMaxFarStalls = 8;
/// With the round-off floor known, the next step aims its truncation at what the floor leaves of tol, but at
/// no less than this share of tol.
constexpr double kMinAimShare = 0.1;
/// Runs that differ by more than this relative amount follow no common trajectory: their difference
/// predicts no step.
constexpr double kUnresolvedPair = 1.0;
/// Differences at or below this relative size are at the round-off level of a run of 1e3..1e6 steps.
constexpr double kRoundOff = 1e-13;
/// A planned pair far below its target starts once more at most this many times coarser (replanned()).
constexpr double kMaxReplanGain = 4.0;
/// A run about to be delivered is verified by a companion at its step over this ratio, which costs this many
/// of its runs.
constexpr double kVerifyRatio = 1.25;

}  // namespace

/// The pilot pair at h0 and h0/2 (a refused step halves h0); sets the first estimate and returns the finer
/// run, never delivered (docs/measurements.md, "Limits, measured": a pilot pair's estimate alone was 25x low;
/// the coarser may be, bounded by finer runs: pilot_answer).
Level Search::pilot(Level& coarse) {
  double h = search_first_step(m_, b_, c_, t_end_);
  for (int k = 0;; ++k) {
    Attempt<Level> pair = attempt([&] {
      coarse = run_at(h, h, tol_ >= kProbeBelowTol);  // it may be the answer (pilot_answer)
      Level fine = run_at(0.5 * coarse.h, h, false);
      // A pair that differs by more than kUnresolvedPair is no trajectory yet: the pair moves down by
      // halvings, each run one more at half the step (their sum at most the last pair's cost), with the same
      // constant c, until it differs by less.
      for (int d = 0; state_distance(coarse.run.final, fine.run.final) > kUnresolvedPair && d < kMaxRefinements; ++d) {
        coarse = std::move(fine);
        coarse.samples_dropped = true;  // it ran without the caller's observers: delivered, it runs again
        fine = run_at(0.5 * coarse.h, h, false);
      }
      estimate_ = pair_estimate(coarse, fine);
      return fine;
    });
    if (pair.value) return std::move(*pair.value);
    if (k >= kMaxRefinements) throw Error(pair.why);
    h *= 0.5;
  }
}

/// A ladder started at a planned step (Accuracy::first_step, a map's plan): the answer at that step and its
/// companion at kCompanionRatio times it with the companion's constant c, as refine() starts a new ladder, in
/// place of the pilot pair. False (rungs empty) where the method breaks down there or the pair follows no
/// common trajectory: the search then starts from its own pilot.
bool Search::seeded(std::vector<Level>& rungs) {
  if (!(seed_ > 0.0)) return false;
  const double h_c = kCompanionRatio * seed_;
  Attempt<bool> pair = attempt([&] {
    rungs.push_back(run_at(h_c, h_c, !delivery_.sink));  // planned_far_below may deliver it
    rungs.push_back(run_at(seed_, h_c, true));
    return state_distance(rungs[0].run.final, rungs[1].run.final) <= kUnresolvedPair;
  });
  if (pair.value && *pair.value) {
    estimate_ = pair_estimate(rungs[0], rungs[1]);
    return true;
  }
  rungs.clear();
  return false;
}

/// A planned pair whose estimate lies far below its target (the row is easier than the pilot it was planned
/// from) starts once more at the step its estimate predicts, at most kMaxReplanGain times coarser: refined from
/// there, the ladder would only go finer and deliver far more accuracy than asked (a map over B at 1e-8:
/// 1e-11). True with the new pair in `rungs`.
bool Search::replanned(std::vector<Level>& rungs, double& h_c) {
  if (replanned_) return false;
  replanned_ = true;
  const double h = seed_;
  seed_ = h * std::min(std::pow(kTarget * tol_ / estimate_, 1.0 / p_), kMaxReplanGain);
  std::vector<Level> coarser;
  if (!seeded(coarser)) return false;
  rungs = std::move(coarser);
  h_c = rungs.front().h;
  return true;
}

/// A planned pair far below its target (the row is easier than the pilot it was planned from) gets a third
/// run at twice its companion's step with the pair's constant c, a quarter of the answer's cost or less; where
/// the three show the method's order (smooth()), the planned answer is trusted as it is: more accurate than
/// asked, but a coarser pair (replanned()) would cost the row as much again where its cost is the far field's,
/// which a larger step with its larger c does not shorten (the thesis's scene at d = 84, B = 0.65, TOL 1e-9:
/// the replanned answer at 2.6x the step took 2,583 evaluations for the planned one's 2,601). True with the
/// run at the front of `rungs`; false, the run dropped, where it breaks down or the order does not show.
bool Search::coarser_rung_confirms(std::vector<Level>& rungs, double h_c) {
  if (rungs.size() != 2) return false;
  Attempt<Level> coarser = attempt([&] { return run_at(2.0 * rungs.front().h, h_c, false); });
  if (!coarser.value) return false;
  rungs.insert(rungs.begin(), std::move(*coarser.value));
  if (smooth(rungs, estimate_)) return true;
  rungs.erase(rungs.begin());
  return false;
}

/// The ladder's first pair: the planned one (seeded) or the pilot's; its constant's step in `h_c`. True for a
/// planned pair, which is judged as refine()'s new ladder is: its estimate is expected near kTarget tol.
bool Search::first_pair(std::vector<Level>& rungs, double& h_c) {
  if (seeded(rungs)) {
    h_c = rungs.front().h;
    return true;
  }
  Level coarse;
  Level fine = pilot(coarse);
  h_c = coarse.h;
  rungs.push_back(std::move(coarse));
  rungs.push_back(std::move(fine));
  return false;
}

/// The refusal of a TOL that finer runs, still differing by `d`, do not reach.
Error Search::out_of_reach(double d) const {
  return Error("tol " + fmt_tol() + " is out of reach of " + std::string(m_.name) +
               " on this scene: runs at finer steps still differ by " + short_number(d) +
               " (round-off amplified by the scene, or resonances that refinement does not remove)");
}

/// The pilot's coarse run itself, where the ladder's first refinement leaves it the best-checked answer:
/// the finest run bounds its error within TOL (their difference over 1 - r^-q, q the lower of p and the
/// order the three runs observe) and the three show at least order p - kOrderSlack (a higher order only
/// means the finer runs err less: the bound stands). It is checked by finer runs, as a verified answer is.
/// Above kProbeBelowTol only.
std::optional<Level> Search::pilot_answer(std::vector<Level>& rungs) {
  if (tol_ < kProbeBelowTol || rungs.size() != 3 || rungs[0].samples_dropped) return std::nullopt;
  const double q = observed_order(rungs[0], rungs[1], rungs[2]);
  const double d = state_distance(rungs[0].run.final, rungs[2].run.final);
  if (!(q >= p_ - kOrderSlack && q >= 1.0 && d > kRoundOff)) return std::nullopt;
  const double e = coarser_bound(rungs[0], rungs[2], q);
  if (!(e <= kAccept * tol_)) return std::nullopt;
  estimate_ = last_estimate_ = e;
  return std::move(rungs[0]);
}

/// The error of `coarse` that its difference from the finer `fine` bounds where three runs show order q: Richardson
/// at the lower of p and q, floored to an integer (as pilot_answer and the answers below take it).
double Search::coarser_bound(const Level& coarse, const Level& fine, double q) const {
  return coarser_run_error(state_distance(coarse.run.final, fine.run.final), coarse.h / fine.h,
                           static_cast<int>(std::floor(std::min<double>(p_, q))));
}

/// Where the pilot's coarse run meets TOL by the pair's own difference, a run at twice its step (half the
/// coarse run's cost, coarser_rung_confirms) judges the pair before any finer run: where the three show the
/// method's order q, the coarse run is delivered, its error the pair's difference over 1 - 2^-min(p, q). The run
/// at twice the step is not delivered: its steps may turn the spin further than any the method chose, which only a
/// run that tracks invariants would show.
/// refine() only goes finer than the pilot's finer run (kMinRefinement), so the ladder's way to the same
/// answer (pilot_answer) costs at least 2.5 coarse runs more: a far pass at TOL 1e-9 (d = 60, B = 0.9),
/// logh-kl6's search 29,817 -> 19,026 evaluations for the same delivered run. A planned pair is judged as
/// refine()'s new ladder is, not here. Above kProbeBelowTol only, as pilot_answer.
std::optional<Level> Search::coarser_pilot_answer(std::vector<Level>& rungs, double h_c, bool planned) {
  if (planned || tol_ < kProbeBelowTol || rungs.size() != 2 || rungs[0].samples_dropped) return std::nullopt;
  const double d = state_distance(rungs[0].run.final, rungs[1].run.final);
  if (!(d > kRoundOff && coarser_run_error(d, rungs[0].h / rungs[1].h, p_) <= kAccept * tol_)) return std::nullopt;
  if (!coarser_rung_confirms(rungs, h_c)) return std::nullopt;  // rungs: 2 h0, h0, h0/2
  const double e = coarser_bound(rungs[1], rungs[2], observed_order(rungs[0], rungs[1], rungs[2]));
  if (!(e <= kAccept * tol_)) {
    rungs.erase(rungs.begin());  // the ladder goes on from the pilot pair, as without the coarser run
    return std::nullopt;
  }
  estimate_ = last_estimate_ = e;
  return std::move(rungs[1]);
}

/// A planned pair far below its target (the row is easier than the pilot it was planned from): where a coarser
/// run confirms the pair (coarser_rung_confirms), its companion is delivered where the pair bounds its error
/// within TOL, at order min(p, q) of the three, and it is sound (assess(): it ran with the caller's invariant
/// checks, at a step up to 4x the pilot's); else the planned answer as it is, as before. Only without a sink
/// (a sweep's rows, an encounter's run from 2L): the companion ran without the caller's observers. Where the
/// coarser run does not confirm the pair, a coarser planned pair (replanned(), `replan` set).
std::optional<Level> Search::planned_far_below(std::vector<Level>& rungs, double& h_c, bool& replan) {
  replan = false;
  if (!coarser_rung_confirms(rungs, h_c)) {
    replan = replanned(rungs, h_c);
    return std::nullopt;
  }
  Level& companion = rungs[1];
  if (delivery_.sink || !companion.run.invariants) return std::nullopt;
  const double e = coarser_bound(companion, rungs[2], observed_order(rungs[0], rungs[1], rungs[2]));
  const Checks sound = checks_for(m_, c_, std::numeric_limits<double>::infinity());
  if (!(e <= kAccept * tol_) || assess(companion.run, sound).outcome != Outcome::ok) return std::nullopt;
  estimate_ = last_estimate_ = e;
  return std::move(companion);
}

/// Runs that share one time-step constant c form a ladder; each new run is estimated from the run before it
/// (Richardson, order p) and checked by the run before that (file comment).
Level Search::ladder() {
  std::vector<Level> rungs;  // runs sharing the constant c of step h_c, coarse to fine
  double h_c = 0.0;
  bool planned = first_pair(rungs, h_c);
  if (std::optional<Level> answer = coarser_pilot_answer(rungs, h_c, planned)) return std::move(*answer);
  double best_bound = std::numeric_limits<double>::infinity();
  int stalled = 0;
  bool verified_finer = false;  // the newest rung is a verification's companion: estimate it first
  for (int k = 0; k < kMaxRefinements; ++k) {
    const double expected = planned          ? kTarget * tol_
                            : verified_finer ? estimate_ * std::pow(rungs.back().h / rungs[rungs.size() - 2].h, p_)
                                             : refine(rungs, h_c);
    verified_finer = false;
    if (k == 0 && !planned) {
      if (std::optional<Level> answer = pilot_answer(rungs)) return std::move(*answer);
      rungs.front().samples = {};
    }
    const bool from_plan = std::exchange(planned, false);
    const std::size_t a = rungs.size() - 2;  // an index: coarser_rung_confirms inserts at the front
    rungs[a].samples = {};  // only the newest run can still be delivered: its predecessors' samples go
    last_estimate_ = estimate_ = pair_estimate(rungs[a], rungs.back());
    const double d = state_distance(rungs[a].run.final, rungs.back().run.final);
    if (from_plan && estimate_ < expected / kAgree && d > kRoundOff) {
      if (std::optional<Level> answer = planned_far_below(rungs, h_c, planned)) return std::move(*answer);
      if (planned) continue;  // not confirmed by a coarser run: a coarser planned pair
    }
    refuse_below_round_off(d);
    if (deliverable(rungs.back(), h_c, trusted(rungs, h_c, expected, d, from_plan))) {
      if (verified(rungs, h_c)) return std::move(rungs.back());
      verified_finer = true;  // its companion joined the ladder
      continue;
    }
    // Estimates that stop falling (round-off, or resonances refinement does not remove) end the search; larger
    // differences are not a floor but a step still outside the asymptotic regime (kStallBelow).
    if (estimate_ < best_bound / kStallFactor) {
      best_bound = estimate_;
      stalled = 0;
    } else if (++stalled < (d > kStallBelow ? kMaxFarStalls : kMaxStalls)) {
      // A stall among runs closer than kStallBelow may be the round-off's: the answer is probed (deliverable()).
      rounding_suspected_ = rounding_suspected_ || d <= kStallBelow;
      continue;
    } else if (d <= tol_) {
      // The finest runs differ by less than tol but their estimates are not trusted (not smooth in h): what
      // they differ by bounds the finer one's error once its own companion agrees (kep-kl6 on a material
      // close pass was refused at every tol with runs 4.98e-12 apart). A refusal never quotes a difference
      // below the tol asked (logh-kl6 at 1e-9: "still differ by 9.39e-10").
      if (verified_at(rungs, h_c, d)) return std::move(rungs.back());
      verified_finer = true;
      stalled = 0;
    } else {
      // The floor is what finer runs still disagree by, not the smallest estimate: an early pair can agree
      // by chance (B = 0.9, b = 1 at tol 1e-12: first estimate 9.9e-15, then three refinements each 4e-12
      // apart, which one of them must be wrong by half of).
      throw out_of_reach(d);
    }
  }
  throw Error("tol " + fmt_tol() + ": " + std::string(m_.name) + " did not reach it in " +
              std::to_string(kMaxRefinements) + " refinements");
}

/// Runs `d` apart at the round-off level (kRoundOff) whose estimate is still above what may be delivered: the
/// TOL is below the method's round-off floor on this scene.
void Search::refuse_below_round_off(double d) const {
  if (d <= kRoundOff && estimate_ > kAccept * tol_)
    throw Error("tol " + fmt_tol() + " is below the round-off floor of " + std::string(m_.name) +
                " on this scene (estimate " + short_number(estimate_) + ")");
}

/// Whether the newest pair's estimate (its runs `d` apart) is trusted: smooth(), or the pair at the round-off
/// level. A new ladder's pair (not a plan's) that reads more than kLowPair below what the coarser runs predicted
/// (`expected`), with its runs farther apart than round-off's amounts (kStallBelow), is judged by a third run
/// at twice its companion's step as well (coarser_rung_confirms): its companion can lie outside the asymptotic
/// range. On estimate_grid.py logh-pefrl at 1e-7 (d = 8, Kz = 5, B = 0.8, Kx = -1) was delivered 1.45e-8 off with
/// a pair's 3.8e-9, which the model had predicted at 3e-8.
bool Search::trusted(std::vector<Level>& rungs, double h_c, double expected, double d, bool from_plan) {
  if (d <= kRoundOff) return true;
  if (!smooth(rungs, expected)) return false;
  return from_plan || rungs.size() != 2 || estimate_ >= expected / kLowPair || d <= kStallBelow ||
         coarser_rung_confirms(rungs, h_c);
}

/// Whether the newest estimate is trusted: the error behaves like C h^p there. The three last runs of the
/// ladder show an order within [p - kOrderSlack, p + kOrderExcess], or (two runs) the estimate is what the
/// model carried over from the coarser runs predicted (`expected`), within kAgree.
bool Search::smooth(const std::vector<Level>& rungs, double expected) const {
  const std::size_t n = rungs.size();
  if (n < 3) return estimate_ <= kAgree * expected && estimate_ >= expected / kAgree;
  // An order far above p is trusted where the triple before showed it too: a scattering run's final state
  // converges faster than h^p throughout (the error at the end of an encounter is that of a processed
  // method), where one run sitting at a zero of the error shows it once.
  const double q = observed_order(rungs[n - 3], rungs[n - 2], rungs[n - 1]);
  const bool again = n >= 4 && observed_order(rungs[n - 4], rungs[n - 3], rungs[n - 2]) > p_ + kOrderExcess;
  return q >= p_ - kOrderSlack && (q <= p_ + kOrderExcess || again);
}

/// Adds the ladder's next run, at the step the estimate predicts for what TOL leaves to truncation; far finer
/// than the ladder so far, it starts a new ladder (h_c changes). Returns the error the model C h^p expects of
/// the new run.
double Search::refine(std::vector<Level>& rungs, double& h_c) {
  // Once a round-off floor was measured (below kProbeBelowTol), the truncation aims at what it leaves.
  const double aim = kTarget * std::max(tol_ - std::max(floor_, 0.0) / kAccept, kMinAimShare * tol_);
  const double predicted = rungs.back().h * std::pow(aim / std::max(estimate_, kRoundOff), 1.0 / p_);
  if (automatic_omega_c(b_, c_, kCompanionRatio * predicted) < kNewConstantGain * rungs.back().omega_c) {
    // Far finer than the ladder so far: a new ladder whose constant c is that of the companion's step, so
    // that the answer does not pay for the coarse runs' larger c in the far field.
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

/// Whether the newest run `l` may be delivered: its estimate (and the round-off floor measured so far) within
/// TOL, and the estimate `trusted`. Below kProbeBelowTol, or where the ladder's estimates stalled at runs
/// closer than kStallBelow (rounding_suspected_), the round-off is probed on `l` itself and added to the
/// estimate; round-off alone above TOL throws. Unprobed, a stalled ladder's last triple can show the order by
/// chance: table 3.1's pass from L = 3200 (b = 3, arrival phase 1) to t = 906 at TOL 1e-10, logh-kl6's runs
/// at ds = 0.0134 .. 0.0054 differed by 1.5e-11, 9.6e-11, 2.4e-10, 5.7e-11, and the last was delivered
/// 1.43e-10 off with an estimate of 2.0e-11; probed, runs that differ only in rounding differ by 2.9e-10.
bool Search::deliverable(const Level& l, double h_c, bool trusted) {
  if (!(estimate_ + std::max(floor_, 0.0) <= kAccept * tol_ && trusted)) return false;
  if (tol_ >= kProbeBelowTol && !rounding_suspected_) return true;
  // Measured on the run that may be delivered: a floor measured on another run is another draw of the
  // round-off (reused from a coarser run, 2 of 256 scenes at tol 1e-12 missed it).
  floor_ = rounding_floor(l, h_c);
  if (floor_ > kAccept * tol_)
    throw Error("tol " + fmt_tol() + " is out of reach of " + std::string(m_.name) +
                " on this scene: runs that differ only in rounding differ by " + short_number(floor_) +
                " (round-off amplified by the scene)");
  // Truncation and round-off add up in the delivered run: its estimate is their sum. Where the sum is above
  // what may be delivered, a finer run lowers the truncation part.
  if (estimate_ + floor_ > kAccept * tol_) return false;
  estimate_ = last_estimate_ = estimate_ + floor_;
  return true;
}

/// Whether the ladder's newest run may be delivered as it is: without verification (auto about one centre:
/// its choices' estimates were measured honest), or when its companion at h/kVerifyRatio, run now, agrees
/// within TOL (their difference over 1 - r^-p: the error of the run at h). A companion that does not agree
/// joins the ladder as its newest run (false): the search goes on from there.
bool Search::verified(std::vector<Level>& rungs, double h_c) { return !verify_ || verified_at(rungs, h_c, estimate_); }

/// The same with the delivered run's estimate `current`, which the companion's can only raise.
bool Search::verified_at(std::vector<Level>& rungs, double h_c, double current) {
  Level finer = run_at(rungs.back().h / kVerifyRatio, h_c, true);
  const double e = coarser_run_error(state_distance(rungs.back().run.final, finer.run.final), rungs.back().h / finer.h, p_);
  if (e + std::max(floor_, 0.0) <= kAccept * tol_) {
    estimate_ = last_estimate_ = std::max(current, e + std::max(floor_, 0.0));
    return true;
  }
  rungs.back().samples = {};
  rungs.push_back(std::move(finer));
  return false;
}

/// The order with which three runs of the ladder converge (accuracy.hpp, observed_order).
double Search::observed_order(const Level& l1, const Level& l2, const Level& l3) const {
  return bodypoint::observed_order(state_distance(l1.run.final, l2.run.final), state_distance(l2.run.final, l3.run.final),
                                  l1.h / l3.h, l2.h / l3.h);
}

/// Richardson's estimate of the finer run's error from a pair at steps h_c > h_f, order p.
double Search::pair_estimate(const Level& c, const Level& f) const {
  return finer_run_error(state_distance(c.run.final, f.run.final), c.h / f.h, p_);
}

}  // namespace bodypoint::adaptive::detail
