#!/usr/bin/env python3
"""Writes the LaTeX macros and table fragments of the research appendix from the drivers' CSVs.

usage: make_macros.py RESULTS_DIR OUT_DIR MODE

Every number the paper states comes from here (paper/bodypoint.tex types none: tests/paper check it).
OUT_DIR/macros.tex holds one \\newcommand per measured figure, named after what it measures
(\\ErrSignEnergy, \\SpeedupThesisSeven, \\MedDThesisEuler, ...); OUT_DIR/tab_*.tex are table bodies.
Macro names are letters only: digits are spelled (lp-y4 -> LpYFour, 1e-07 -> Seven).

One module per section of the paper (paper/macros/): front (the first page, the machine, the build),
errata, methods, chapter4, close, work_precision, stability, long_time, scattering; common holds what
they share. This file runs them in the order the macros were always written.
"""
import os
import sys

from catalogue import load as load_catalogue
import timing_rule
from macros.chapter4 import claims_table, harness, java_agreement, sweeps
from macros.close import close_table, ladder_budget, reference_error, speedup_table, third_party_speedup
from macros.common import Macros, read_csv, revision_of
from macros.errata import errata
from macros.front import build_options, build_time, contention, platform, timing_discipline
from macros.long_time import long_time
from macros.methods import geometry_tables, methods_table
from macros.scattering import l_cost, scattering
from macros.stability import appendix, ensembles, map_scale_text, stress
from macros.work_precision import by_tol, estimate_branches, estimate_cost, estimate_grid, far_field


def main():
    if len(sys.argv) not in (4, 5):
        sys.exit("usage: make_macros.py RESULTS_DIR OUT_DIR MODE [FIGURES_DIR]")
    res, out, mode = sys.argv[1:4]
    figs = sys.argv[4] if len(sys.argv) == 5 else None  # make_figures.py's lost.csv: empty panels
    load_catalogue(res)
    os.makedirs(out, exist_ok=True)
    M = Macros(timing_rule.Rule.of(res))
    _, header = read_csv(os.path.join(res, "d_sweep.csv"))
    M.add("Revision", f"\\texttt{{{revision_of(header)}}}", math_mode=False)
    M.add("BuildMode", mode, math_mode=False)
    platform(res, M)
    build_time(res, M)
    build_options(res, M)
    timing_discipline(res, M)
    errata(res, M)
    sweeps(res, M)
    methods_table(res, out, M)
    geometry_tables(res, out)
    claims_table(res, out, M)
    java_agreement(M)
    harness(res, M)
    reference_error(res, M)
    ladder_budget(res, M)
    speedup_table(res, out, M)
    third_party_speedup(res, M)
    close_table(res, out, M)
    by_tol(res, out, M)
    estimate_grid(res, M)
    estimate_cost(res, M)
    estimate_branches(res, out, M)
    far_field(res, out, M)
    stress(res, out, M)
    appendix(res, M)
    ensembles(res, out, M)
    map_scale_text(res, M)
    scattering(res, M)
    l_cost(res, M)
    long_time(res, out, M)
    contention(res, figs, M)
    M.write(os.path.join(out, "macros.tex"))
    print(f"wrote {len(M.defs)} macros and the tables to {out}")


if __name__ == "__main__":
    main()
