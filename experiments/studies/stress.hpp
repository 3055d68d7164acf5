// bodypoint study --name stress: hostile scenes for one method of each family (stress.cpp).
#pragma once

#include "bodypoint/run.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace bodypoint::cli {

struct StressRow {
  std::string case_name, method;
  Outcome outcome = Outcome::refused;
  std::string reason;
  double max_rel_dE = std::nan("");
  double err_estimate = std::nan("");  ///< the run's estimated relative error (ErrorEstimate; NaN: none)
  long steps = 0;
  double wall_s = 0.0;
};

/// Every case x method; `each` sees every row as it is done (progress).
std::vector<StressRow> run_stress(bool quick, const std::function<void(const StressRow&)>& each = {});

/// The rows as CSV (with reasons) and as a Markdown table.
void write_stress(std::ostream& csv, std::ostream& md, const std::vector<StressRow>& rows);

}  // namespace bodypoint::cli
