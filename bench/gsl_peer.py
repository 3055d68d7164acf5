#!/usr/bin/env python3
"""GSL as bodypoint drives it against GSL as its own users drive it (issue: peers driven as their users
drive them).

bench/gsl_plain.c is a stand-alone C program: a plain C right-hand side and gsl_odeiv2_driver_apply,
nothing of bodypoint. This script runs it and bodypoint's gsl-rk8pd / gsl-rkf45 (through the Python
module, no invariants, no error estimate: the run work-precision times) on the named scenes' initial
states, interleaved: each of REPEATS rounds runs the plain program (a warm-up, then its timed samples)
and then bodypoint's peer (warm after the first round). A sample of either is a batch of identical
integrations lasting at least MIN_SAMPLE_S, its time divided by their number. It prints, per scene, stepper and tolerance, both
force-evaluation counts, the medians and spreads of both times and their ratio, and exits 1 when
bodypoint's peer costs more than PEER_MARGIN above the plain program, per force evaluation.

Usage (from the repository, after the build):
    PYTHONPATH=build/python /usr/bin/python3 bench/gsl_peer.py build/bin/gsl_plain [--out FILE.csv]
"""
import argparse
import csv
import os
import statistics
import subprocess
import sys

import bodypoint as bp

# bodypoint's peer may cost at most this share more per force evaluation than the plain C program: the
# issue's bound (within 10 %).
PEER_MARGIN = 0.10
REPEATS = 7          # interleaved rounds (the timing rules ask for at least 5)
SAMPLES_PER_ROUND = 3  # timed samples of each side per round (the plain program's after its warm-up)
MIN_SAMPLE_S = 2e-3    # a sample lasts at least this long (bench/gsl_plain.c's MIN_REPEAT_S)
TOLS = [1e-4, 1e-7, 1e-10]
STEPPERS = ["rk8pd", "rkf45"]


def scenes():
    """The named scenes of work-precision (lib/bodypoint/scenes.hpp) as (name, scene, t_end, centres)."""
    thesis = bp.thesis_scene()
    out = [("thesis", thesis, 50.0, [(0.0, 0.0, 0.0, -2.0)]),
           ("close", bp.thesis_scene(Kz=0.1, d=0.05), 80.0, [(0.0, 0.0, 0.0, -2.0)]),
           ("material", bp.thesis_scene(B=0.0), 50.0, [(0.0, 0.0, 0.0, -2.0)])]
    s = bp.Stepper(thesis, "gsl-rk8pd", 1e-7).state
    vec = lambda x: "[" + ", ".join(repr(float(c)) for c in x) + "]"
    two = bp.parse_scene(
        "[[centre]]\nposition = [0.0, 0.0, 0.0]\nA = -2.0\n"
        "[[centre]]\nposition = [40.0, 6.0, 0.0]\nA = -1.0\n"
        f"[[body]]\nm = 1.0\nB = 0.7\nJ = 1.0\nR = {vec(s['R'])}\nv = {vec(s['v'])}\nw = {vec(s['w'])}\n")
    out.append(("two-centres", two, 60.0, [(0.0, 0.0, 0.0, -2.0), (40.0, 6.0, 0.0, -1.0)]))
    return out


def plain_args(plain, stepper, tol, t_end, scene, centres, B):
    s = bp.Stepper(scene, "gsl-rk8pd", 1e-7).state
    state = [repr(float(x)) for x in list(s["R"]) + list(s["v"]) + list(s["w"])]
    cs = [repr(float(x)) for c in centres for x in c]
    return [plain, stepper, repr(tol), repr(t_end), str(SAMPLES_PER_ROUND), "1.0", repr(B), "1.0"] + state + cs


def spread(xs):
    """Interquartile range over the median, as experiments/stopwatch.hpp states the commands' spread."""
    q1, m, q3 = statistics.quantiles(xs, n=4, method="inclusive")
    return (q3 - q1) / m if m > 0 else 0.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("plain", help="the gsl_plain program (build/bin/gsl_plain)")
    ap.add_argument("--out", help="also write the table as CSV (atomically)")
    args = ap.parse_args()
    rows, worst = [], 0.0
    print("| scene | stepper | TOL | force evals (bodypoint, plain) | bodypoint [ms] | spread | plain C [ms] "
          "| spread | bodypoint / plain per evaluation |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, scene, t_end, centres in scenes():
        B = 0.0 if name == "material" else 0.7
        for stepper in STEPPERS:
            for tol in TOLS:
                argv = plain_args(args.plain, stepper, tol, t_end, scene, centres, B)
                ours, plain, ev_ours, ev_plain = [], [], 0, 0
                for _ in range(REPEATS):
                    out = subprocess.run(argv, check=True, capture_output=True, text=True).stdout.split("\n")
                    plain += [float(line.split()[1]) for line in out if line]
                    ev_plain = int(out[0].split()[0])
                    for _ in range(SAMPLES_PER_ROUND):
                        total, n = 0.0, 0
                        while total < MIN_SAMPLE_S:  # the step loops' own times, summed
                            r = bp.integrate(scene, "gsl-" + stepper, tol=tol, t_end=t_end, invariants=False,
                                             estimate_error=False)
                            total, n = total + r["wall_s"], n + 1
                        ours.append(total / n)
                        ev_ours = r["force_evals"]
                mo, mp = statistics.median(ours), statistics.median(plain)
                ratio = (mo / ev_ours) / (mp / ev_plain)
                worst = max(worst, ratio)
                rows.append([name, stepper, tol, ev_ours, ev_plain, mo, spread(ours), mp, spread(plain), ratio])
                print(f"| {name} | {stepper} | {tol:.0e} | {ev_ours}, {ev_plain} | {mo * 1e3:.3g} | "
                      f"{spread(ours):.0%} | {mp * 1e3:.3g} | {spread(plain):.0%} | {ratio:.3f} |")
    print(f"\nworst ratio {worst:.3f} (bound {1 + PEER_MARGIN:.2f}); {REPEATS} interleaved rounds of "
          f"{SAMPLES_PER_ROUND} samples each side, medians")
    if args.out:
        tmp = args.out + ".tmp"
        with open(tmp, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["scene", "stepper", "tol", "force_evals", "plain_force_evals", "wall_s", "spread",
                        "plain_wall_s", "plain_spread", "ratio_per_eval"])
            w.writerows(rows)
        os.replace(tmp, args.out)
    return 1 if worst > 1 + PEER_MARGIN else 0


if __name__ == "__main__":
    sys.exit(main())
