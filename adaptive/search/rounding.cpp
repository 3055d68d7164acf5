// bodypoint: the search's round-off probe (search.hpp). Below kProbeBelowTol (tolerance.hpp) a run about to
// be delivered is repeated kProbeRuns times, all but one with its roundings changed (a fictitious step moved
// by a relative k kProbeShift, or k fixed steps more: the truncation error moves by far less than tol), one
// from its start moved by kStartShift. An encounter amplifies round-off, which Richardson cannot tell from
// truncation; runs that differ only in rounding measure it (docs/measurements.md, "Limits, measured").
#include "search.hpp"

#include "bodypoint/adaptive/methods.hpp"

#include <algorithm>

namespace bodypoint::adaptive::detail {

/// The most that the run `l` and its kProbeRuns repeats with other roundings differ by. Repeats from one
/// start share what the scene makes of the start's own rounding: on a near head-on pass (kep-y4 at tol
/// 1e-12) the runs at N, N+1 and N+2 steps differed by 3.4e-13 and were all 1.75e-11 from a binary128
/// reference, whose start is the exact one; the moved start shows that amplification.
double Search::rounding_floor(const Level& l, double h_c) {
  double floor = 0.0;
  for (int k = 1; k < kProbeRuns; ++k) {
    const double h = is_time_transformed(m_) ? l.h * (1.0 - k * kProbeShift) : t_end_ / static_cast<double>(l.steps + k);
    floor = std::max(floor, state_distance(l.run.final, run_at(h, h_c, false).run.final));
  }
  const Body moved = start_moved(kStartShift);
  return std::max(floor, state_distance(l.run.final, run_at(l.h, h_c, false, &moved).run.final));
}

/// The body with its start moved by a relative `shift`: R scaled by 1 + shift, v by 1 - shift.
Body Search::start_moved(double shift) const {
  Body moved = b_;
  moved.s0.R *= 1.0 + shift;
  moved.s0.v *= 1.0 - shift;
  return moved;
}

}  // namespace bodypoint::adaptive::detail
