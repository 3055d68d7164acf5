// bodypoint: the step search behind --tol (bodypoint/adaptive/tolerance.hpp), one concern per file:
//   start.cpp       where a search starts (its first step) and how a step becomes a way of advancing time
//   runs.cpp        the search's runs: its budget, the observers of a run that may be delivered, delivery
//   ladder.cpp      methods of order p: the pilot pair and the ladder of runs, Richardson's estimate
//                   checked against the runs before it (the search's steps are described there)
//   rounding.cpp    the round-off probe below kProbeBelowTol: repeats that differ only in rounding
//   exact_pair.cpp  methods without an order (ks, far-ip): a pair's difference bounds the error
// Each tuned constant's measurement is in docs/measurements.md, "Tuned constants". Internal: not installed.
#pragma once

#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/detail/run_support.hpp"
#include "bodypoint/detail/run_parts.hpp"

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace bodypoint::adaptive::detail {

using bodypoint::detail::short_number;

/// A run is delivered when its estimated error is at most this fraction of tol.
constexpr double kAccept = 0.8;
/// A refinement that repeats a prediction, and an order-free pair (exact_pair.cpp), step down by this factor.
constexpr double kMinRefinement = 1.25;
/// The search gives up after this many refinements in a row that did not lower its estimate by kStallFactor.
constexpr int kMaxStalls = 3;
constexpr double kStallFactor = 2.0;
/// Refinements (and halvings of a refused step) before the search gives up.
constexpr int kMaxRefinements = 48;

/// A limit of the search itself (its budget, the smallest step it takes): final, unlike a method's
/// refusal of one step, which only halves the pilot's step.
struct SearchLimit : Error {
  using Error::Error;
};

/// What a step of the search gave: its value, or (none) why the method broke down at that step (a driver's
/// Error: a time transformation that stopped advancing, a non-finite state, an iteration that did not
/// converge), which the search answers with a smaller step. A limit of the search and a stop from outside
/// are not a step's answer: they end the search (thrown on).
template <class T>
struct Attempt {
  std::optional<T> value;
  std::string why;  ///< of no value: the method's reason
};

/// Runs `step` (the runs of one step of the search) and returns what it gave as a value: the one place
/// where the search turns a method's breakdown into a result.
template <class F>
auto attempt(F&& step) -> Attempt<decltype(step())> {
  try {
    return {step(), {}};
  } catch (const SearchLimit&) {
    throw;
  } catch (const StoppedOnRequest&) {
    throw;
  } catch (const Error& e) {
    return {std::nullopt, e.what()};
  }
}

/// One run of the search, with what it ran and, while it may still be delivered, its samples.
struct Level {
  double h = 0.0;
  long steps = 0;
  double omega_c = 0.0;
  RunResult run;
  std::vector<KeptSample> samples;  ///< kept until the run is known to be the delivered one
  bool samples_dropped = false;     ///< more than kMaxKeptSamples (runs.cpp): the delivery runs it again
  Advance how;                      ///< what it ran, for that run again
};

/// The way of advancing time at step h: fictitious steps ds = h to t_end for time-transformed methods,
/// otherwise the fixed steps of at most h that land on t_end.
Advance step_advance(const MethodInfo& m, double h, double t_end, double dt_out);

/// One search: its runs, what they measured so far, and the run it delivers.
class Search {
 public:
  Search(const MethodInfo& m, const Body& b, const std::vector<Centre>& c, const Accuracy& a,
         const RunOptions& delivery, bool verify)
      : m_(m), b_(b), c_(c), tol_(a.tol), t_end_(a.t_end), dt_out_(a.dt_out), seed_(a.first_step),
        p_(effective_order(m, b)), delivery_(delivery), verify_(verify) {}

  /// The delivered run with its estimate (runs.cpp), from the ladder (order p) or the exact pair.
  ToleranceResult search();

 private:
  // runs.cpp
  Level run_at(double h, double h_c, bool may_deliver, const Body* from = nullptr);
  [[nodiscard]] RunOptions run_options(double omega_c, bool may_deliver) const;
  void replay(const Level& best);
  [[nodiscard]] double expected_evals(const Advance& how) const;
  [[nodiscard]] std::string basis() const;

  // ladder.cpp
  Level pilot(Level& coarse);
  bool seeded(std::vector<Level>& rungs);
  bool first_pair(std::vector<Level>& rungs, double& h_c);
  [[nodiscard]] Error out_of_reach(double d) const;
  bool replanned(std::vector<Level>& rungs, double& h_c);
  bool coarser_rung_confirms(std::vector<Level>& rungs, double h_c);
  std::optional<Level> planned_far_below(std::vector<Level>& rungs, double& h_c, bool& replan);
  std::optional<Level> pilot_answer(std::vector<Level>& rungs);
  std::optional<Level> coarser_pilot_answer(std::vector<Level>& rungs, double h_c, bool planned);
  Level ladder();
  double refine(std::vector<Level>& rungs, double& h_c);
  [[nodiscard]] bool smooth(const std::vector<Level>& rungs, double expected) const;
  void refuse_below_round_off(double d) const;
  bool trusted(std::vector<Level>& rungs, double h_c, double expected, double d, bool from_plan);
  bool deliverable(const Level& l, double h_c, bool trusted);
  bool verified(std::vector<Level>& rungs, double h_c);
  bool verified_at(std::vector<Level>& rungs, double h_c, double current);
  [[nodiscard]] double pair_estimate(const Level& c, const Level& f) const;
  [[nodiscard]] double coarser_bound(const Level& coarse, const Level& fine, double q) const;
  [[nodiscard]] double observed_order(const Level& l1, const Level& l2, const Level& l3) const;

  // rounding.cpp
  double rounding_floor(const Level& l, double h_c);
  [[nodiscard]] Body start_moved(double shift) const;

  // exact_pair.cpp
  Level exact_flow();
  static std::string pair_text();

  [[nodiscard]] std::string fmt_tol() const { return short_number(tol_); }

  const MethodInfo& m_;
  const Body& b_;
  const std::vector<Centre>& c_;
  double tol_, t_end_, dt_out_;
  double seed_;  ///< Accuracy::first_step: a planned step (0: the search's own pilot)
  bool replanned_ = false;  ///< the planned start was moved once (replanned())
  int p_;
  RunOptions delivery_;
  bool verify_;  ///< a run about to be delivered is checked against a companion at a finer step (ladder.cpp)
  double estimate_ = 0.0, last_estimate_ = std::numeric_limits<double>::quiet_NaN();
  double floor_ = -1.0;  ///< the round-off floor last measured (below kProbeBelowTol), -1 before
  bool rounding_suspected_ = false;  ///< the ladder's estimates stalled at runs closer than kStallBelow
  /// Every run's step and end, for the delivered run's companion (search()).
  struct Ran {
    double h;
    State final;
    double t_end;
  };
  std::vector<Ran> ran_;
  double spent_evals_ = 0.0, total_wall_ = 0.0;
  long total_evals_ = 0;
  int runs_ = 0;
};

}  // namespace bodypoint::adaptive::detail
