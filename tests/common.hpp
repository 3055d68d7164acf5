// Shared helpers for the tests: scenes of the thesis and a log-log slope fit.
#pragma once

#include "bodypoint/model.hpp"
#include "bodypoint/order_fit.hpp"
#include "bodypoint/run.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace bodypoint::test {

/// Thesis table 3.1 with the given changes applied by the caller.
inline Scene table31(double B = 0.7) {
  SceneParams sp;
  sp.B = B;
  return thesis_scene(sp);
}

inline double rel_err(const Vec3& a, const Vec3& ref) { return (a - ref).norm() / ref.norm(); }

// Ladders of steps h0 / sqrt(2)^k, k = 0..kLadder-1 (the fit: bodypoint/order_fit.hpp).
constexpr int kLadder = 24;

/// Runs a ladder of kLadder points, point(k) returning (step, error) for k = 0, 1, ...; fits the
/// asymptotic slope, checks that enough points were fitted, and prints the ladder under `label`.
template <class Point>
double ladder_slope(const std::string& label, Point&& point) {
  std::vector<std::pair<double, double>> all;
  std::string log;
  for (int k = 0; k < kLadder; ++k) {
    const auto [h, e] = point(k);
    char buf[48];
    std::snprintf(buf, sizeof buf, " %.3g:%.2e", h, e);
    log += buf;
    all.emplace_back(h, e);
  }
  std::size_t used = 0;
  const double slope = asymptotic_slope(all, &used);
  EXPECT_GE(used, kFitPoints) << label << log;
  std::printf("  %-30s slope %.3f (%zu points)%s\n", label.c_str(), slope, used, log.c_str());
  return slope;
}

}  // namespace bodypoint::test
