#!/usr/bin/env python3
"""Where the time goes with several centres, and what far-ip under --tol costs (docs/measurements.md, "Limits, measured").

Prints two tables, timed by the project's rules (a warm-up call of each configuration, then interleaved
repeats; medians of wall and CPU time, spread = interquartile range / median of the wall times):
1. Nanoseconds per force evaluation on the thesis scene (one centre), two-centres and three-centres (the
   named scenes), for the splittings lp-kl6, logh-kl6 and ttl-kl6 and GSL's rk8pd: from
   `bodypoint work-precision` on those scenes (its own interleaved timing), the median over each ladder's
   runs of wall time / force evaluations, runs of at least MIN_EVALS evaluations whose time is not flagged.
   A bodypoint evaluation is a kick stage (its force and the exact drift after it); rk8pd's is one
   evaluation of the right-hand side.
2. The accuracy mode on the far pass of figure 11 (the thesis scene with Kz = 0.1, d = 50, t = 80): auto's
   whole search against far-ip's (`method="far-ip", tol=TOL`), force evaluations of the whole search and
   its time, through the Python module.

Usage (from the repository, after the build; about a minute, on a machine doing nothing else):
    PYTHONPATH=build/python /usr/bin/python3 bench/several_centres.py [build/bin/bodypoint] [--repeats 7]
"""
import argparse
import csv
import statistics
import subprocess
import tempfile
import time

import bodypoint as bp

SCENES = ["thesis", "two-centres", "three-centres"]
METHODS = ["lp-kl6", "logh-kl6", "ttl-kl6", "gsl-rk8pd"]
# Runs shorter than this are mostly per-run overhead (the material scene's microseconds).
MIN_EVALS = 2000
TOLS = [1e-7, 1e-10, 1e-12]


def per_evaluation(binary):
    with tempfile.NamedTemporaryFile(suffix=".csv") as out:
        subprocess.run([binary, "work-precision", "--scenes", ",".join(SCENES), "--methods", ",".join(METHODS),
                        "--out", out.name], check=True, stdout=subprocess.DEVNULL)
        rows = list(csv.DictReader(line for line in open(out.name) if not line.startswith("#")))
    print("ns per force evaluation (median over the ladder's unflagged runs of >= %d evaluations; runs)" % MIN_EVALS)
    print("| method | " + " | ".join(SCENES) + " |")
    print("|---|" + "---|" * len(SCENES))
    for m in METHODS:
        cells = []
        for s in SCENES:
            ns = [float(r["wall_s"]) / float(r["force_evals"]) * 1e9 for r in rows
                  if r["scene"] == s and r["method"] == m and not r["flag"] and float(r["force_evals"]) >= MIN_EVALS]
            cells.append(f"{statistics.median(ns):.1f} ({len(ns)})" if ns else "-")
        print(f"| {m} | " + " | ".join(cells) + " |")


def far_pass(repeats):
    scene = bp.thesis_scene(d=50, Kz=0.1)
    configs = [(method, tol) for tol in TOLS for method in ("auto", "far-ip")]
    call = lambda c: bp.integrate(scene, method=c[0], tol=c[1], t_end=80, invariants=False)
    first = {c: call(c)["bodies"][0] for c in configs}  # the warm-up call
    times = {c: [] for c in configs}
    for _ in range(repeats):
        for c in configs:
            w0, c0 = time.perf_counter(), time.process_time()
            call(c)
            times[c].append((time.perf_counter() - w0, time.process_time() - c0))
    print(f"\nfar pass (Kz = 0.1, d = 50, t = 80): the whole --tol search, {repeats} interleaved repeats")
    print("| TOL | asked | method | force evaluations | estimate | wall [ms] | CPU [ms] | spread |")
    print("|---|---|---|---|---|---|---|---|")
    for c in configs:
        wall = sorted(t[0] for t in times[c])
        med = statistics.median(wall)
        q1, q3 = statistics.quantiles(wall, n=4)[0], statistics.quantiles(wall, n=4)[2]
        b = first[c]
        print(f"| {c[1]:.0e} | {c[0]} | {b['method']} | {b['search_force_evals']} | {b['err_estimate']:.2e} | "
              f"{med * 1e3:.3f} | {statistics.median(t[1] for t in times[c]) * 1e3:.3f} | {(q3 - q1) / med:.2f} |")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binary", nargs="?", default="build/bin/bodypoint")
    parser.add_argument("--repeats", type=int, default=7, help="interleaved timed repeats (at least 5)")
    args = parser.parse_args()
    if args.repeats < 5:
        parser.error("--repeats: at least 5 (the project's timing rules)")
    per_evaluation(args.binary)
    far_pass(args.repeats)
