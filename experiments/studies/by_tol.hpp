// `bodypoint work-precision --by-tol`: auto and every peer with the same requested tolerance.
#pragma once

#include "bodypoint/scenes.hpp"
#include "stopwatch.hpp"

#include <ostream>
#include <vector>

namespace bodypoint::cli {

/// Runs auto and every step-size-controlled peer with each tolerance on each scene; writes the rows
/// to csv (when given) and the Markdown summary table to summary. Times follow `rules` (stopwatch.hpp).
void run_by_tolerance(const std::vector<NamedScene>& scenes, const std::vector<double>& tols, const TimingRules& rules,
                      double max_evals, std::ostream* csv, std::ostream& summary);

}  // namespace bodypoint::cli
