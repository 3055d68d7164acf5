#!/usr/bin/env python3
"""How well a cost model from catalogue data would choose auto's method (issue #55, item 2), from the
work-precision ladders of a paper build (no run of its own).

For each time-transformed method m of one family the model knows its order p, its force evaluations per
step s and an error constant k_m fitted on a reference scene (err = k_m ds^p, the median over the ladder's
rungs with 1e-12 < err < 1e-3). On every scene the family's Verlet ladder gives the scene's amplitude
A = k_verlet(scene) / k_verlet(reference); the model predicts ds_m = min(cap, (aim TOL / (A k_m))^(1/p)) and
picks the m with the fewest predicted evaluations s / ds_m. Printed: the picked method's actual cost (its
coarsest rung meeting TOL with the next finer rung meeting it too) over the family's cheapest by the same rule.

    bench/choice_model.py paper/results-quick [--family logh] [--cap 0.2] [--reference close]

With --ratios it prints instead each method's error constant over the family's Verlet, k_m / k_verlet, on every
scene and their geometric mean: how far a step predicted from a Verlet pilot pair by that mean may be off
(docs/measurements.md, "Limits, measured": the pilot pair run by the family's Verlet, measured and not kept).
"""
import argparse
import csv
import math
import os
import statistics
from collections import defaultdict

SCENES = ["thesis", "close", "material", "long", "two-centres", "three-centres"]
TOLS = [1e-4, 1e-7, 1e-10, 1e-12]
AIM = 0.3  # the search's kTarget: a predicted step aims at 0.3 TOL
FIT_RANGE = (1e-12, 1e-3)  # rungs below are at round-off, above outside the asymptotic range


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(l for l in f if not l.startswith("#")))


def load(results, family):
    """The catalogue's rows, the work-precision ladders by (scene, method), and the family's candidates."""
    meth = {r["method"]: r for r in rows(os.path.join(results, "methods.csv"))}
    ladders = defaultdict(list)
    for r in rows(os.path.join(results, "work_precision.csv")):
        try:
            h, e = float(r["h"]), float(r["err_rel"])
        except ValueError:
            continue
        if math.isfinite(e):
            ladders[(r["scene"], r["method"])].append((h, e, int(r["force_evals"])))
    for k in ladders:
        ladders[k].sort(reverse=True)
    cands = [m for m, r in meth.items() if m.startswith(family + "-") and r["advance"] == "fictitious"
             and int(r["order"]) > 0]
    return meth, ladders, cands


def constant(meth, ladders, scene, m):
    """The error constant k of e = k h^p, fitted on the ladder's points in FIT_RANGE."""
    p = int(meth[m]["order"])
    ks = [e / h ** p for h, e, _ in ladders.get((scene, m), []) if FIT_RANGE[0] < e < FIT_RANGE[1]]
    return statistics.median(ks) if ks else None


def actual(ladders, scene, m, tol):
    """The evaluations of the ladder's coarsest point delivering TOL whose next finer one does too."""
    pts = ladders.get((scene, m), [])
    for i, (_, e, n) in enumerate(pts):
        if e <= tol and (i + 1 >= len(pts) or pts[i + 1][1] <= tol):
            return n
    return None


def print_ratios(meth, ladders, cands, verlet):
    print(f"{'method':12s} " + " ".join(f"{s:>13s}" for s in SCENES) + "  geometric mean")
    for m in sorted(cands):
        per = {s: k / v for s in SCENES
               if (k := constant(meth, ladders, s, m)) and (v := constant(meth, ladders, s, verlet))}
        mean = math.exp(statistics.fmean(math.log(x) for x in per.values())) if per else float("nan")
        print(f"{m:12s} " + " ".join(f"{per[s]:13.3g}" if s in per else f"{'-':>13s}" for s in SCENES) + f"  {mean:.3g}")


def compare(meth, ladders, cands, verlet, a):
    """Per scene and TOL, the model's pick against the family's cheapest; the ratios."""
    k_ref = {m: constant(meth, ladders, a.reference, m) for m in cands}
    ratios = []
    for scene in SCENES:
        k_v = constant(meth, ladders, scene, verlet)
        if k_v is None or not k_ref.get(verlet):
            continue
        amp = k_v / k_ref[verlet]
        for tol in TOLS:
            predicted = [(int(meth[m]["evals_per_step"]) / min(a.cap, (AIM * tol / (amp * k_ref[m])) ** (1.0 / int(meth[m]["order"]))), m)
                         for m in cands if k_ref[m]]
            best = min(((n, m) for m in cands if (n := actual(ladders, scene, m, tol))), default=None)
            if not predicted or not best:
                continue
            pick = min(predicted)[1]
            n = actual(ladders, scene, pick, tol)
            ratio = n / best[0] if n else float("nan")
            if n:
                ratios.append(ratio)
            print(f"{scene:13s} {tol:7.0e}  picks {pick:12s} {n or '-':>8}  best {best[1]:12s} {best[0]:>8}  {ratio:.2f}x")
    return ratios


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("results", help="a paper build's results directory (work_precision.csv, methods.csv)")
    ap.add_argument("--family", default="logh", help="logh or ttl (three-centres attracts: ttl only)")
    ap.add_argument("--cap", type=float, default=0.2, help="the largest fictitious step the model predicts")
    ap.add_argument("--reference", default="close", help="the scene the error constants are fitted on")
    ap.add_argument("--ratios", action="store_true", help="print k_m / k_verlet per scene and their geometric mean")
    a = ap.parse_args()
    meth, ladders, cands = load(a.results, a.family)
    verlet = a.family + "-verlet"
    if a.ratios:
        print_ratios(meth, ladders, cands, verlet)
        return
    ratios = compare(meth, ladders, cands, verlet, a)
    if ratios:
        print(f"{len(ratios)} cases: picked over best {min(ratios):.2f}-{max(ratios):.2f}x, "
              f"median {statistics.median(ratios):.2f}x")


if __name__ == "__main__":
    main()
