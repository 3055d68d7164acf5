"""Section 'Methods': the method table and the geometry tables."""

import math
import os
import re
import statistics

from catalogue import rows as catalogue_rows
from macros.common import (
    bench_ns, camel, count, latex_text, lost_column, num, read_csv, sci, timing_flagged, timing_ns, tt,
)


def measured_orders(res):
    """{method: (encounter slope, orbit slope)} from orders.csv (empty cells: not run there)."""
    rows, _ = read_csv(os.path.join(res, "orders.csv"))
    return {r["method"]: (num(r["encounter"]), num(r["orbit"])) for r in rows}


def geometry_latex(text):
    """The catalogue's geometry text ("|K2|^2 exact, K2Q with one centre", "B != 0") in LaTeX."""
    math = {"|K2|^2": "$|\\vect K_2|^2$", "K2Q": "$\\vect K_{2Q}$", "!=": "$\\ne$"}
    parts = re.split(r"(\|K2\|\^2|K2Q|!=)", text)
    return "".join(math.get(p, latex_text(p)) for p in parts)


def geometry_tables(res, out):
    """From the catalogue (methods.csv, as catalogue.py loaded it): tab_families, what each family's flows preserve, and
    tab_compositions, each composition table's order, stages, symmetry and citation."""
    rows = catalogue_rows()
    with open(os.path.join(out, "tab_families.tex"), "w") as f:
        for name in dict.fromkeys(r["family_name"] for r in rows):
            geometry = next(r["geometry"] for r in rows if r["family_name"] == name).split("; ")[0]
            f.write(f"{name} & {geometry_latex(geometry)} \\\\\n")
    tables = {}
    for r in rows:
        if r["table"] and r["table"] not in tables:
            tables[r["table"]] = r
    with open(os.path.join(out, "tab_compositions.tex"), "w") as f:
        for tag, r in tables.items():
            symmetric = "yes" if r["geometry"].endswith("; symmetric") else "no"
            f.write(f"{tt(tag)} & {r['order']} & {r['stages']} & {symmetric} & {latex_text(r['reference'])} \\\\\n")


def methods_table(res, out, M):
    rows, _ = read_csv(os.path.join(res, "force_evals.csv"))
    # Thesis table 4.1 against the catalogue: which of its seven counts are ours, which differ.
    printed = {r["method"]: r for r in rows if r.get("thesis_table_4_1")}
    differ = [r for r in printed.values() if r["thesis_table_4_1"] != r["evals_per_step"]]
    M.add("TableFourOneMethods", count(len(printed)))
    M.add("TableFourOneAgree", count(len(printed) - len(differ)))
    M.add("TableFourOneDiffers", ", ".join(f"{tt(r['method'])} ({r['thesis_table_4_1']} there, {r['evals_per_step']} here)"
                                           for r in differ) or "none", math_mode=False)
    orders, tns = measured_orders(res), timing_ns(res)
    bns, bench_flags = bench_ns(res, M.rule)
    tflags = timing_flagged(res)
    with open(os.path.join(out, "tab_methods.tex"), "w") as f:
        for r in rows:
            m = r["method"]
            nominal = "exact" if m == "ks" else r["order"] if r["order"] != "0" else "var."
            enc, orb = orders.get(m, (float("nan"), float("nan")))
            meas = " & ".join(f"{x:.2f}" if math.isfinite(x) else "--" for x in (enc, orb))
            # A time that does not count reads "fl." (flagged), one not taken "--".
            b = f"{bns[m]:.0f}" if m in bns else "\\emph{fl.}" if m in bench_flags else "--"
            t = f"{tns[m]:.0f}" if m in tns else "\\emph{fl.}" if m in tflags else "--"
            f.write(f"{tt(m)} & {nominal} & {meas} & {r['evals_per_step']} & {sci(num(r['measured_per_step']), 3)} & {b} & {t} \\\\\n")
            if math.isfinite(enc):
                M.add(f"Order{camel(m)}", f"{enc:.2f}")
            if math.isfinite(orb):
                M.add(f"OrderOrbit{camel(m)}", f"{orb:.2f}")
            if m in bns:
                M.add(f"BenchNs{camel(m)}", f"{bns[m]:.0f}")
    M.add("NumMethods", count(len(rows)))
    # Does cost follow force evaluations? ns per evaluation (bench) of every method whose stage is a force
    # evaluation (not the Kepler split's Kepler solve), from the measured evaluations per step.
    per_eval = {r["method"]: bns[r["method"]] / num(r["measured_per_step"]) for r in rows
                if r["method"] in bns and not r["method"].startswith("kep-") and num(r["measured_per_step"]) > 0}
    if not bns:
        lost_column(M, "table~\\ref{tab:methods}, column bench", list(bench_flags.values()))
    if not tns:
        lost_column(M, "table~\\ref{tab:methods}, column timing", list(tflags.values()))
    if per_eval:
        lo, hi = min(per_eval, key=per_eval.get), max(per_eval, key=per_eval.get)
        M.add("NsPerEval", f"per force evaluation a step costs ${per_eval[lo]:.0f}$~ns ({tt(lo)}) to "
              f"${per_eval[hi]:.0f}$~ns ({tt(hi)}), median ${statistics.median(per_eval.values()):.0f}$~ns "
              "(bench, the Kepler split's Kepler solves left out)", math_mode=False)
    else:
        M.add("NsPerEval", "what a step costs per force evaluation is untimed in this copy (every "
              "\\cmd{bench\\_steps} time flagged)", math_mode=False)
    both = [m for m in bns if m in tns]
    gap = [max(bns[m], tns[m]) / min(bns[m], tns[m]) for m in both]
    M.add("BenchTimingAgreement", f"agree within a factor of ${max(gap):.2f}$ (median ${statistics.median(gap):.2f}$) "
          f"for every method both time with a counted time" if gap else
          "are not compared in this copy: no method has a counted time in both", math_mode=False)
    ab4 = [bns.get(m) for m in ("ab4-thesis", "ab4")]
    M.add("AbFourBench", f"${ab4[0]:.0f}$~ns per step against ${ab4[1]:.0f}$~ns, bench" if all(ab4) else
          "its \\cmd{bench\\_steps} times flagged in this copy", math_mode=False)
