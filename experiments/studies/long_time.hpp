// bodypoint study --name long-time: bound orbits over many periods (long_time.cpp).
#pragma once

#include <filesystem>

namespace bodypoint::cli {

/// Writes long_time.csv into `dir`: three bound scenes (a material point's Kepler ellipse, a spinning body on
/// the same orbit, an orbit about two attracting centres), each method at a fixed step (or tolerance per step)
/// to `periods` periods (0: 10^3 quick, 10^5 otherwise), its invariants' and its state's errors at log-spaced
/// times. Error unless periods is 0 or a finite number of at least kLongTimeFirstPeriods.
void write_long_time_study(const std::filesystem::path& dir, bool quick, double periods = 0.0);

/// The first output time, in periods: a span shorter than this has no rows.
inline constexpr double kLongTimeFirstPeriods = 10.0;

}  // namespace bodypoint::cli
