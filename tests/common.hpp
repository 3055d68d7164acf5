// Shared helpers for the tests: scenes of the thesis and a log-log slope fit.
#pragma once

#include "bodypoint/model.hpp"
#include "bodypoint/run.hpp"

#include <cmath>
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

}  // namespace bodypoint::test
