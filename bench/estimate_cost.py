#!/usr/bin/env python3
"""What a run's error estimate costs (issue #55): `bodypoint simulate` with its default estimate against
`--no-error-estimate`, CPU time of the whole command, warm, interleaved repeats.

Each case is run once to warm the caches, then REPEATS times alternating with and without the estimate;
the CPU time is the child's user + system time (resource.getrusage), the wall time beside it. Prints per
case the medians, the spread (min-max) and the force evaluations of the run and of its estimate, and the
ratio of the medians. Take it on a machine doing nothing else: a timing beside a build or a test says
nothing (the script prints the load average before and after).

With --python DIR (the build's python/ folder), the same for the Python module's integrate(), timed in
this process (time.process_time, warm): bodypoint.integrate(thesis_scene(), method, h, t_end) with and
without estimate_error.

With --csv FILE every case is also written as a row: the medians, the spread of each side (interquartile
range over the median), how far each side's median wall time exceeds its CPU time (a waiting process:
contended), the force evaluations; paper/make_macros.py judges them by the paper's timing rule.

Usage (from the repository, after the build):
    /usr/bin/python3 bench/estimate_cost.py [build/bin/bodypoint] [--repeats 7] [--python build/python] [--csv FILE]
"""
import argparse
import csv
import json
import os
import resource
import statistics
import subprocess
import sys
import time

# The cases: the README's run (the default scene, lp-y4 at h = 1e-4, 500,000 steps) and runs by step of
# the methods auto delivers, on the thesis's scene.
CASES = [
    ("default simulate", []),
    ("lp-kl8 h=0.05 t=40", ["--method", "lp-kl8", "--h", "0.05", "--t-end", "40"]),
    ("logh-kl6 ds=0.05 t=40", ["--method", "logh-kl6", "--h", "0.05", "--t-end", "40"]),
    ("lp-verlet h=0.002 t=40", ["--method", "lp-verlet", "--h", "0.002", "--t-end", "40"]),
]


def spread(xs):
    """Interquartile range over the median (quartiles by linear interpolation), as the paper's rule reads it."""
    q = statistics.quantiles(xs, n=4, method="inclusive")
    return (q[2] - q[0]) / statistics.median(xs)


ROWS = []  # one per case, for --csv


def report(name, w, wo, evals_run, evals_estimate, basis):
    """Prints a case's line and keeps its row: w, wo are (CPU s, wall s) per repeat with and without."""
    cw, cwo = [x[0] for x in w], [x[0] for x in wo]
    ww, wwo = [x[1] for x in w], [x[1] for x in wo]
    print(f"{name} | {statistics.median(cw):.3f} ({min(cw):.3f}-{max(cw):.3f}) | {statistics.median(cwo):.3f} "
          f"({min(cwo):.3f}-{max(cwo):.3f}) | {statistics.median(cw) / statistics.median(cwo):.2f} | "
          f"{statistics.median(ww):.3f} / {statistics.median(wwo):.3f} | {evals_run} + {evals_estimate} | {basis[:70]}")
    ROWS.append(dict(case=name, repeats=len(w), cpu_with_s=statistics.median(cw), cpu_without_s=statistics.median(cwo),
                     ratio=statistics.median(cw) / statistics.median(cwo), spread_with=spread(cw),
                     spread_without=spread(cwo), wait_with=statistics.median(ww) / statistics.median(cw) - 1,
                     wait_without=statistics.median(wwo) / statistics.median(cwo) - 1, force_evals=evals_run,
                     estimate_force_evals=evals_estimate, basis=basis))


def timed(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall, json.loads(out)


# The Python cases: the README's run and one of a method auto delivers, as integrate() keywords.
PY_CASES = [
    ("python integrate lp-y4 h=1e-4 t=50", dict(method="lp-y4", h=1e-4, t_end=50.0)),
    ("python integrate lp-kl8 h=0.05 t=40", dict(method="lp-kl8", h=0.05, t_end=40.0)),
]


def python_cases(folder, repeats):
    sys.path.insert(0, folder)
    import bodypoint  # noqa: E402 (the build's module, found through --python)

    scene = bodypoint.thesis_scene()

    def one(kw, estimate):
        t0, w0 = time.process_time(), time.perf_counter()
        r = bodypoint.integrate(scene, kw["method"], h=kw["h"], t_end=kw["t_end"], estimate_error=estimate)
        return time.process_time() - t0, time.perf_counter() - w0, r

    for name, kw in PY_CASES:
        one(kw, True), one(kw, False)  # warm
        w, wo = [], []
        for _ in range(repeats):
            w.append(one(kw, True))
            wo.append(one(kw, False))
        body = w[0][2]["bodies"][0]
        report(name, w, wo, body["force_evals"], body["estimate_force_evals"], body["err_basis"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary", nargs="?", default="build/bin/bodypoint")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--python", help="the build's python/ folder: time the module's integrate() too")
    ap.add_argument("--csv", help="also write the cases as CSV rows to this file")
    a = ap.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    print("case | CPU s with estimate (min-max) | without | ratio of medians | wall with / without | "
          "force evals run + estimate | estimate basis")
    for name, args in CASES:
        with_cmd = [a.binary, "simulate", "--json", "--quiet", *args]
        without_cmd = with_cmd + ["--no-error-estimate"]
        timed(with_cmd), timed(without_cmd)  # warm
        w, wo = [], []
        for _ in range(a.repeats):
            w.append(timed(with_cmd))
            wo.append(timed(without_cmd))
        run = w[0][2]
        report(name, w, wo, run["force_evals"], run["estimate_force_evals"], run["err_basis"])
    if a.python:
        python_cases(a.python, a.repeats)
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    if a.csv:
        with open(a.csv + ".tmp", "w", newline="") as f:
            out = csv.DictWriter(f, fieldnames=list(ROWS[0]))
            out.writeheader()
            out.writerows(ROWS)
        os.replace(a.csv + ".tmp", a.csv)


if __name__ == "__main__":
    main()
