// bodypoint: the measured order of a method from a ladder of steps (log-log slope above round-off).
// Shared by the convergence tests (tests/lib/test_convergence.cpp) and `bodypoint study --name orders`.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

namespace bodypoint {

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

// Ladders of steps h0 / sqrt(2)^k, k = 0..kLadder-1. The round-off plateau of a ladder is the median
// error of its kPlateauPoints smallest steps (the ladders run well into it: 1e-16..1e-14 relative with
// compensated summation). Points within a factor kPlateauMargin of it (so that rounding moves them by
// at most ~3%) are left out, and so are points below kPlateau when the ladder never reached its
// plateau (low orders); the ladder is cut at its first point below that level. The slope is fitted to
// the kFitPoints smallest steps before the cut: the most asymptotic points rounding does not disturb.
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

}  // namespace bodypoint
