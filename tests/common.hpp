// Shared helpers for the tests: scenes of the thesis and a log-log slope fit.
#pragma once

#include "bodypoint/model.hpp"
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

/// Least-squares slope of log(err) against log(h).
inline double loglog_slope(const std::vector<std::pair<double, double>>& h_err) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(h_err.size());
  for (auto [h, e] : h_err) {
    const double x = std::log(h), y = std::log(e);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

inline double rel_err(const Vec3& a, const Vec3& ref) { return (a - ref).norm() / ref.norm(); }

// Ladders of steps h0 / sqrt(2)^k, k = 0..kLadder-1. The round-off plateau of a ladder is the median
// error of its kPlateauPoints smallest steps (the ladders run well into it: 1e-16..1e-14 relative with
// compensated summation). Points within a factor kPlateauMargin of it (so that rounding moves them by
// at most ~3%) are left out, and so are points below kPlateau when the ladder never reached its
// plateau (low orders); the ladder is cut at its first point below that level. The slope is fitted to
// the kFitPoints smallest steps before the cut: the most asymptotic points rounding does not disturb.
constexpr int kLadder = 24;
constexpr double kPlateau = 1e-12;
constexpr double kPlateauMargin = 30.0;
constexpr std::size_t kPlateauPoints = 5;
constexpr std::size_t kFitPoints = 3;

/// Fitted order of (h, error) pairs ordered from large to small h; *used = points fitted.
inline double asymptotic_slope(const std::vector<std::pair<double, double>>& all, std::size_t* used) {
  std::vector<double> tail;
  for (std::size_t i = all.size() - std::min(kPlateauPoints, all.size()); i < all.size(); ++i)
    tail.push_back(all[i].second);
  std::sort(tail.begin(), tail.end());
  const double cut = std::min(kPlateau, kPlateauMargin * tail[tail.size() / 2]);
  // The descending branch only: from the largest step until the ladder first reaches the plateau
  // (round-off grows with the number of steps, so later points can rise above the cut again).
  std::vector<std::pair<double, double>> pts;
  for (const auto& p : all) {
    if (!(p.second > cut)) break;
    pts.push_back(p);
  }
  if (pts.size() > kFitPoints) pts.erase(pts.begin(), pts.end() - static_cast<long>(kFitPoints));
  *used = pts.size();
  return pts.size() >= 2 ? loglog_slope(pts) : 0.0;
}

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
