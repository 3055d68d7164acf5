// bodypoint study --name long-time: bound orbits over many periods (long_time.cpp).
#pragma once

#include <filesystem>

namespace bodypoint::cli {

/// Writes long_time.csv into `dir`: three bound scenes (a material point's Kepler ellipse, a spinning body on
/// the same orbit, an orbit about two attracting centres), each method at a fixed step (or tolerance per step)
/// to 10^3 (quick) or 10^5 periods, its invariants' and its position's errors at log-spaced times.
void write_long_time_study(const std::filesystem::path& dir, bool quick);

}  // namespace bodypoint::cli
