// bodypoint: the rounding draws of a run's estimate (estimate/parts.hpp): at the scene's rounding level a pair of
// runs can agree by chance; more draws of the rounding are added and their sum taken as a bound.
#include "estimate/parts.hpp"

#include <functional>
#include <string>
#include <utility>

namespace bodypoint::detail {

/// `draw(k)`: the k-th draw (k >= 1), from the start moved rounding_way(k); `o`: the draws' options;
/// `options`: the run's (its events index them); `what`: what they are, for the basis; `coarse`: the coarse
/// companion's final state where the draws are coarse runs (measured from it), nullptr where they repeat the run.
void add_rounding_draws(ErrorEstimate& e, const BodyResult& r, const Options& options, const Options& o,
                        const std::function<BodyResult(int)>& draw, const std::string& what, const State* coarse) {
  if (!at_rounding_level(e)) return;
  const double pair = e.value;
  for (int k = 1; k < ErrorEstimate::kRoundingDraws; ++k) {
    const BodyResult p = draw(k);
    if (!ended_alike(r, options, p, o)) {
      e.force_evals += p.total_force_evals();
      e.wall_s += p.run.wall_s;
      continue;
    }
    add_rounding_spread(e, coarse ? *coarse : r.run.final, p.run.final, p.total_force_evals(), p.run.wall_s, what);
  }
  if (coarse) sum_of_draws(e);
  else bound_from_draws(e, pair);
}

/// The k-th draw of the rounding (k = 0: the first) as a scalar run: from the start moved rounding_way(k),
/// advancing as how_of(k) (repeats off the run's grid, or the coarse companion and its draws: coarse_draw).
std::function<BodyResult(int)> rerun_draws(const Body& body, std::function<Advance(int)> how_of, const Options& o,
                                           const Rerun& rerun) {
  return [&body, how_of = std::move(how_of), &o, &rerun](int k) {
    Body moved = body;
    moved.s0 = start_moved_by_rounding(body.s0, rounding_way(k));
    return rerun(moved, how_of(k), o);
  };
}

Advance off_grid(const Advance& how, int k) {
  if (const auto* f = std::get_if<FixedSteps>(&how))
    return FixedSteps{f->h * static_cast<double>(f->steps) / static_cast<double>(f->steps + k), f->steps + k};
  if (const auto* f = std::get_if<FictitiousSteps>(&how)) {
    FictitiousSteps moved = *f;
    moved.ds *= 1.0 + k * bodypoint::kProbeShift;
    return moved;
  }
  return how;
}

double rounding_way(int k) { return k % 2 == 1 ? -1.0 : 1.0; }

void bound_from_draws(ErrorEstimate& e, double pair) {
  e.value = pair + ErrorEstimate::kRoundingBound * (e.value - pair);
  e.basis += "; the repeats' part taken " + short_number(ErrorEstimate::kRoundingBound) + " times: a bound from " +
             std::to_string(ErrorEstimate::kRoundingDraws) + " draws of the rounding";
}

void sum_of_draws(ErrorEstimate& e) {
  e.basis += "; their sum a bound: " + std::to_string(ErrorEstimate::kRoundingDraws + 1) +
             " draws of the rounding, the pair's and the coarse run's from its start moved";
}

bool at_rounding_level(const ErrorEstimate& e) { return e.value < kRoundingLevel; }

State start_moved_by_rounding(State s, double way) {
  s.R *= 1.0 + way * bodypoint::kStartShift;
  s.v *= 1.0 - way * bodypoint::kStartShift;
  return s;
}

void add_rounding_spread(ErrorEstimate& e, const State& run, const State& repeat, long force_evals, double wall_s,
                         const std::string& what) {
  e.force_evals += force_evals;
  e.wall_s += wall_s;
  if (!(repeat.R.allFinite() && repeat.v.allFinite())) return;
  const double spread = bodypoint::state_distance(run, repeat);
  e.value += spread;
  e.basis += "; plus " + short_number(spread) + " from " + what + " (the estimate is at the scene's rounding level)";
}

}  // namespace bodypoint::detail
