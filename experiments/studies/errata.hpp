// bodypoint study errata: one runnable demonstration per erratum of the thesis and of its published
// code, each measured (docs/physics.md "Errata"; paper/bodypoint.tex, section "Errata").
#pragma once

#include <ostream>

namespace bodypoint::cli {

/// Writes `key,value,description` rows (the keys become LaTeX macros in paper/make_macros.py).
void write_errata(std::ostream& csv);

}  // namespace bodypoint::cli
