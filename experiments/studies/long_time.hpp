// bodypoint study --name long-time: bound orbits over many periods (long_time.cpp).
#pragma once

#include <filesystem>

namespace bodypoint::cli {

/// What `study --name long-time` was asked for.
struct LongTimeRequest {
  bool quick = false;
  double periods = 0.0;  ///< the span of each orbit (0: 10^3 quick, 10^5 otherwise)
  unsigned threads = 1;  ///< the runs (a method on a scene) go on this many threads
  bool resume = false;   ///< go on from the journal of an interrupted run (long_time.csv.journal)
};

/// Writes long_time.csv into `dir`: three bound scenes (a material point's Kepler ellipse, a spinning body on
/// the same orbit, an orbit about two attracting centres), each method at a fixed step (or tolerance per step)
/// to the span asked for, its invariants' and its state's errors at log-spaced times. Every run stops every
/// kChunkPeriods periods and at the output times, and its state and counters there go into a journal, so that
/// a span of 10^7 periods can be run in sittings (a signal or --max-seconds ends a sitting; --resume goes on
/// bit for bit). Error unless periods is 0 or a finite number of at least kLongTimeFirstPeriods.
void write_long_time_study(const std::filesystem::path& dir, const LongTimeRequest& request);

/// The first output time, in periods: a span shorter than this has no rows.
inline constexpr double kLongTimeFirstPeriods = 10.0;

}  // namespace bodypoint::cli
