// bodypoint: timing runs (run time against the number of steps), shared by `timing` and `study`.
#pragma once

#include "bodypoint/model.hpp"
#include "bodypoint/bodypoint.hpp"
#include "bodypoint/run.hpp"
#include "stopwatch.hpp"

#include <ostream>
#include <string>
#include <vector>

namespace bodypoint::cli {

struct TimingSpec {
  std::vector<long> ns;
  std::vector<const MethodInfo*> methods;
  SceneParams base;
  double h = kDefaultStep;
  double tol = kDefaultStepTolerance;
  long repeats = 5;
  long warmup = 1;
  double max_seconds = 0.0;  ///< refuse a study whose calibrated time exceeds this (0: no budget)
};

struct TimingRow {
  long n;
  const MethodInfo* method;
  Timing time;  ///< per run, under the timing rules (stopwatch.hpp)
  long force_evals;
};

std::vector<TimingRow> run_timing(const TimingSpec& spec, bool progress);
void write_timing_csv(std::ostream& os, const TimingSpec& spec, const std::vector<TimingRow>& rows,
                      const std::string& command);

}  // namespace bodypoint::cli
