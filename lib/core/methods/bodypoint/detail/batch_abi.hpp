// bodypoint: what the per-width batch units (batch_w.cpp) and the dispatcher (batch.cpp) exchange:
// plain arrays and C-style functions only, so that no inline code crosses between units built for
// different instruction sets.
#pragma once

#include <cstddef>

namespace bodypoint::batch::abi {

/// One member in: m, B, J, A, R (3), v (3), w (3).
inline constexpr std::size_t kIn = 13;
/// One member out: R, v, w at the end (9), max |dE|/|E0|, max |dK2^2|/K2^2_0, max |dK2Q|, closest
/// distance to the centre, distance at the start, largest spin angle of a step, smallest cosine of a
/// step's turn about the centre.
inline constexpr std::size_t kOut = 16;

/// splitting::drift_functions(x) as {S1, C1, S3}, built for the baseline (batch.cpp).
void scalar_drift_functions(double x, double* out);

/// A run's cancellation as the units see it: called with `context` every kPollStride steps (detail/run_parts.hpp),
/// true ends the run; the units then return kStopped. Built for the baseline (batch.cpp), so the units
/// load no atomic of their own.
using Poll = bool (*)(const void* context);
/// What a unit's run returns when its Poll ended it.
inline constexpr long kStopped = -2;

}  // namespace bodypoint::batch::abi

#define BODYPOINT_BATCH_DECLARE(ns)                                                                          \
  namespace bodypoint::batch::ns {                                                                           \
  std::size_t width();                                                                                       \
  bool supports(int kernel);                                                                                 \
  long run(int kernel, const double* in, std::size_t count, double h, long steps, double* out,             \
           abi::Poll poll, const void* context);                                                             \
  }
