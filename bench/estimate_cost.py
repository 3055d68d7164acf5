#!/usr/bin/env python3
"""What a run's error estimate costs (issue #55): `bodypoint simulate` with its default estimate against
`--no-error-estimate`, CPU time of the whole command, warm, interleaved repeats.

Each case is run once to warm the caches, then REPEATS times alternating with and without the estimate;
the CPU time is the child's user + system time (resource.getrusage), the wall time beside it. Prints per
case the medians, the spread (min-max) and the force evaluations of the run and of its estimate, and the
ratio of the medians. Take it on a machine doing nothing else: a timing beside a build or a test says
nothing (the script prints the load average before and after).

Usage (from the repository, after the build):
    /usr/bin/python3 bench/estimate_cost.py [build/bin/bodypoint] [--repeats 7]
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import time

# The cases: the README's run (the default scene, lp-y4 at h = 1e-4, 500,000 steps) and runs by step of
# the methods auto delivers, on the thesis's scene.
CASES = [
    ("default simulate", []),
    ("lp-kl8 h=0.05 t=40", ["--method", "lp-kl8", "--h", "0.05", "--t-end", "40"]),
    ("logh-kl6 ds=0.05 t=40", ["--method", "logh-kl6", "--h", "0.05", "--t-end", "40"]),
    ("lp-verlet h=0.002 t=40", ["--method", "lp-verlet", "--h", "0.002", "--t-end", "40"]),
]


def timed(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall, json.loads(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary", nargs="?", default="build/bin/bodypoint")
    ap.add_argument("--repeats", type=int, default=7)
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
        cw, cwo = [x[0] for x in w], [x[0] for x in wo]
        ww, wwo = [x[1] for x in w], [x[1] for x in wo]
        run = w[0][2]
        print(f"{name} | {statistics.median(cw):.3f} ({min(cw):.3f}-{max(cw):.3f}) | {statistics.median(cwo):.3f} "
              f"({min(cwo):.3f}-{max(cwo):.3f}) | {statistics.median(cw) / statistics.median(cwo):.2f} | "
              f"{statistics.median(ww):.3f} / {statistics.median(wwo):.3f} | {run['force_evals']} + "
              f"{run['estimate_force_evals']} | {run['err_basis'][:70]}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
