// bodypoint: the search's runs (search.hpp). Each run is counted against the search's budget; a run that
// may be delivered carries the caller's observers, its samples kept aside until it is delivered, so that
// nothing is integrated twice; the delivered run's samples then go to the caller's sink.
#include "search.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/accuracy.hpp"
#include "bodypoint/detail/run_parts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace bodypoint::adaptive::detail {
namespace {

/// Budget of force evaluations (or KS steps) over all runs of one search (docs/measurements.md, "Tuned constants").
constexpr double kMaxEvals = 2e9;
/// The samples a run that may be delivered keeps for the caller's sink, at most (112 bytes each: 117 MB);
/// beyond, the delivered run is made again with the sink (docs/measurements.md, "Tuned constants").
constexpr std::size_t kMaxKeptSamples = std::size_t{1} << 20;

}  // namespace

ToleranceResult Search::search() {
  Level best = p_ > 0 ? ladder() : exact_flow();
  ToleranceResult out;
  out.h = best.h;
  out.steps = best.steps;
  out.omega_c = best.omega_c;
  out.err_estimate = estimate_;
  out.basis = basis();
  out.result = std::move(best.run);
  out.runs = runs_;
  out.total_force_evals = total_evals_;
  out.total_wall_s = total_wall_;
  // The companion: the run at the step nearest the delivered one's among the others, the latest of equals.
  double nearest = std::numeric_limits<double>::infinity();
  for (const Ran& x : ran_) {
    const double apart = std::abs(std::log(x.h / best.h));
    if (apart > 0.0 && apart <= nearest && std::isfinite(apart)) {
      nearest = apart;
      out.companion = ToleranceResult::Companion{x.final, x.t_end};
    }
  }
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

std::string Search::basis() const {
  return (p_ > 0                                            ? std::string("Richardson over its runs")
          : m_.traits.search == SearchStrategy::field_pair ? "what " + pair_text() + " differ by"
                                                            : "what runs at fictitious steps ds and ds/" +
                                                                  short_number(kMinRefinement) +
                                                                  " differ by: the KS flow is exact") +
         (floor_ > 0.0 ? ", plus runs that differ only in rounding" : "");
}

/// Runs the method at step h (ds for time-transformed methods; a fixed step is rounded to t_end/n)
/// with the time-step constant that the step h_c calls for (time-transformed methods; a pair of
/// runs compared by Richardson must share it to be one method). A run that may be delivered
/// carries the observers the caller asked for, its samples kept aside.
Level Search::run_at(double h, double h_c, bool may_deliver, const Body* from) {
  const bool samples = may_deliver && delivery_.sink;
  const Advance how = step_advance(m_, h, t_end_, samples ? dt_out_ : 0.0);
  RunOptions o = run_options(automatic_omega_c(b_, c_, h_c), may_deliver);
  Level l;
  SampleSink keep;
  if (samples) {
    keep = [&l](const Sample& x) {
      if (l.samples_dropped) return;
      if (l.samples.size() < kMaxKeptSamples) return l.samples.push_back(KeptSample::of(x));
      l.samples = {};
      l.samples_dropped = true;
    };
    o.sink = &keep;
  }
  const double expected = expected_evals(how);
  if (spent_evals_ + expected > kMaxEvals)
    throw SearchLimit("tol " + fmt_tol() + " is out of reach of " + std::string(m_.name) +
                      " within 2e9 force evaluations (last estimate " + short_number(last_estimate_) + ")");
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
  ran_.push_back(Ran{l.h, l.run.final, l.run.t_end});
  spent_evals_ += static_cast<double>(std::max(l.run.force_evals, l.run.steps));
  total_wall_ += l.run.wall_s;
  total_evals_ += l.run.force_evals;
  ++runs_;
  return l;
}

/// The options of a search's run with constant c omega_c: the caller's cancel, and where it may be
/// delivered, the caller's observers (invariants, every k-th step; its sink is the caller's to attach).
RunOptions Search::run_options(double omega_c, bool may_deliver) const {
  RunOptions o;
  o.omega_c = omega_c;
  o.cancel = delivery_.cancel;
  o.track_invariants = may_deliver && delivery_.track_invariants;
  if (may_deliver) {
    o.every = delivery_.every;
    o.inside_steps = delivery_.inside_steps;
  }
  return o;
}

/// The delivered run made again with the caller's sink, where it had more samples than were kept: the
/// same steps and constant c give the same states; the sink's Flow::stop ends its samples, not the run.
void Search::replay(const Level& best) {
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

double Search::expected_evals(const Advance& how) const {
  if (const auto* fixed = std::get_if<FixedSteps>(&how))
    return static_cast<double>(fixed->steps) * std::max(1, m_.evals_per_step);
  return 0.0;  // unknown in advance; the budget is checked against what was spent
}

}  // namespace bodypoint::adaptive::detail
