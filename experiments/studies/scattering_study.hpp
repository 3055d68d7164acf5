// `bodypoint study --name scattering`: the deflection function theta(b) of the thesis's scene, for a
// material point against Rutherford's formula and for spinning bodies (scattering_study.cpp).
#pragma once

#include <filesystem>

namespace bodypoint::cli {

/// Writes scattering.csv (one row per series and impact parameter) and scattering_summary.csv (one row
/// per series) into dir.
void write_scattering_study(const std::filesystem::path& dir, bool quick, unsigned threads);

/// Writes L_cost.csv: what an encounter at its limit L -> infinity costs against the start distance L (table
/// 3.1 given by b = 3 and arrival phase 1, L = 50 .. 10^5, auto at tol 1e-8), beside the thesis's fixed step's
/// evaluations to the same departure.
void write_L_cost(const std::filesystem::path& dir, bool quick);

}  // namespace bodypoint::cli
