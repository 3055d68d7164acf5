// `bodypoint study --name scattering`: the deflection function theta(b) of the thesis's scene, for a
// material point against Rutherford's formula and for spinning bodies (scattering_study.cpp).
#pragma once

#include <filesystem>

namespace bodypoint::cli {

/// Writes scattering.csv (one row per series and impact parameter) and scattering_summary.csv (one row
/// per series) into dir.
void write_scattering_study(const std::filesystem::path& dir, bool quick, unsigned threads);

}  // namespace bodypoint::cli
