// bodypoint: the search of a method without an order p (search.hpp): ks (exact in fictitious time) and
// far-ip (spectral in its step; its error the iteration's, the alias's and the rounding's, far_field.hpp).
// Two runs at steps h and h/kMinRefinement bound the error by what they differ by. far-ip's error is mostly
// the scene's amplified rounding, which one pair draws once: its second run starts from the start moved by
// kFarStartShift, and a third run at h from the start moved the other way by kStartShift; the estimate is the
// larger difference. Below kProbeBelowTol the third run gives way to the round-off probe (rounding.cpp), added
// to the pair's difference. An estimate above what tol allows halves the step (a step too coarse for the
// field errs more), until kMaxStalls halvings in a row did not halve it: the floor it met. A step the method
// refuses (far-ip: its iteration does not converge there) is halved too. Measurements: docs/measurements.md,
// "Tuned constants".
#include "search.hpp"

#include <algorithm>
#include <limits>
#include <string>

namespace bodypoint::adaptive::detail {
namespace {

/// far-ip's pair starts its finer run from the start moved by this relative amount: one unit in the last
/// place, the rounding the start's conversion to momenta makes.
constexpr double kFarStartShift = std::numeric_limits<double>::epsilon();

}  // namespace

Level Search::exact_flow() {
  double h = search_first_step(m_, b_, c_, t_end_);
  const bool far = m_.traits.search == SearchStrategy::field_pair;
  const Body moved = start_moved(kFarStartShift), rounded = start_moved(-kStartShift);
  double best = std::numeric_limits<double>::infinity();
  int stalled = 0;
  for (int k = 0;; ++k) {
    // A pair accepted (its finer-step run's partner delivered), or not yet (none: a finer pair next).
    Attempt<std::optional<Level>> pair = attempt([&]() -> std::optional<Level> {
      Level a = run_at(h, h, true);
      const Level b = run_at(h / kMinRefinement, h, false, far ? &moved : nullptr);
      estimate_ = std::max(state_distance(a.run.final, b.run.final), std::numeric_limits<double>::epsilon());
      if (far && tol_ >= kProbeBelowTol) {
        estimate_ = std::max(estimate_, state_distance(a.run.final, run_at(h, h, false, &rounded).run.final));
      } else if (far) {
        // Below kProbeBelowTol the ladder's rounding probe (kProbeRuns draws) is added, as for the ladder's
        // answer: at 1e-13 on a swing round an attracting centre, after 5 halvings the pair and the one moved
        // start agreed to 4.8e-14 for an error of 2.2e-13.
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
      if (!far || k >= kMaxRefinements || stalled >= kMaxStalls)
        throw SearchLimit("tol " + fmt_tol() + " is below what " + std::string(m_.name) + " delivers on this scene: " +
                          (far ? "the estimate from " + pair_text() + " was at least " : "runs differ by ") +
                          short_number(best) + (far ? " at every step it tried" : ""));
      return std::nullopt;
    });
    if (pair.value && *pair.value) return std::move(**pair.value);
    if (!pair.value && (!far || k >= kMaxRefinements)) throw Error(pair.why);
    h *= 0.5;
  }
}

/// far-ip's runs, as its estimate's basis and its refusal name them.
std::string Search::pair_text() {
  return "runs at steps h and h/" + short_number(kMinRefinement) + " and from starts moved by a rounding";
}

}  // namespace bodypoint::adaptive::detail
