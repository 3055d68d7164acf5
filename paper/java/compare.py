#!/usr/bin/env python3
"""Compares `bodypoint study --name published` with the thesis's own Java solvers, run point by point.

usage: compare.py RESULTS_DIR CLASSPATH OUT_CSV

For every row of RESULTS_DIR/published_{d,L,h,Kx}_sweep.csv it runs `java -cp CLASSPATH Harness SWEEP
VALUE METHOD` (Harness.java: the thesis code's solvers at its harnesses' settings) and writes both maximal
energy and |K2|^2 deviations, the relative difference of the final positions and the Java loop's steps.
"""
import concurrent.futures
import csv
import os
import subprocess
import sys

SWEEPS = ["d", "L", "h", "Kx"]


def rows_of(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def harness_value(sweep, row):
    v = float(row[sweep])
    if sweep == "d":  # bodypoint's d is y + Kz/K1 for the start R0 = (-200, y, 0) = (-200, d' - 1, 0)
        return round(v - float(row.get("Kz", 4.998)) / float(row.get("K1", 4.9993)) + 1.0)
    return v


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    res, classpath, out = sys.argv[1:]
    jobs = []
    for sweep in SWEEPS:
        for r in rows_of(os.path.join(res, f"published_{sweep}_sweep.csv")):
            jobs.append((sweep, harness_value(sweep, r), r))

    def run(job):
        sweep, value, r = job
        p = subprocess.run(["java", "-cp", classpath, "Harness", sweep, repr(value), r["method"]],
                           capture_output=True, text=True, check=True)
        return job, p.stdout.strip().split(",")

    with concurrent.futures.ThreadPoolExecutor(os.cpu_count() or 1) as ex, open(out + ".tmp", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["sweep", "value", "method", "outcome", "max_rel_dE", "java_max_rel_dE", "max_rel_dK2sq",
                    "java_max_rel_dK2sq", "rel_diff_R", "java_steps"])
        for (sweep, value, r), j in ex.map(run, jobs):
            R = [float(x) for x in j[3:6]]
            ours = [float(r[k]) for k in ("Rx", "Ry", "Rz")]
            eR = sum((a - b) ** 2 for a, b in zip(ours, R)) ** 0.5 / sum(b * b for b in R) ** 0.5
            w.writerow([sweep, value, r["method"], r["outcome"], r["max_rel_dE"], j[1], r["max_rel_dK2sq"], j[2],
                        f"{eR:.3e}", j[6]])
    os.replace(out + ".tmp", out)


if __name__ == "__main__":
    main()
