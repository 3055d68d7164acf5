#!/usr/bin/env python3
"""The far field of a spinning body: what bounds the step there (docs/developers.md, "Limits, measured").

Prints two tables:
1. The error of the exact splittings lp-y4 and lp-kl6 at fixed steps h on a pass that stays far from the
   centre (the thesis scene with Kz = 0.1, d = 50, t = 80), against the angle Omega_so h that one step
   turns the spin by. The error is smooth in h below pi per step and jumps at pi, 2 pi, 4 pi: a step
   longer than the spin period lands between resonances, and the error stops being the C h^p that
   Richardson's estimate assumes.
2. Where the accuracy mode's delivered run spends its steps on the close scene (Kz = 0.1, d = 0.05,
   t = 80): the share of steps taken farther than r from the centre.

Usage (from the repository, after the build):
    PYTHONPATH=build/python /usr/bin/python3 bench/far_field.py [build/bin/bodypoint]
"""
import os
import subprocess
import sys
import tempfile

import numpy as np
import bodypoint as bp

T_END = 80.0
STEPS = [0.1, 0.2, 0.3, 0.4, 0.45, 0.5, 0.6, 0.7, 0.8, 0.9, 0.916, 0.95, 1.0, 1.2, 1.4, 1.6, 1.83, 2.0, 2.5, 3.0]
METHODS = ["lp-y4", "lp-kl6"]
TOLS = ["1e-4", "1e-7", "1e-10"]
RADII = [5, 10, 20, 50]


def distance(b, ref):
    return max(np.linalg.norm(b["R"] - ref["R"]) / np.linalg.norm(ref["R"]),
               np.linalg.norm(b["v"] - ref["v"]) / np.linalg.norm(ref["v"]))


def resonances():
    m, B, J, K1 = 1.0, 0.7, 1.0, 5.0  # the thesis's table 3.1, stated so that Omega_so is this scene's
    scene = bp.thesis_scene(m=m, B=B, J=J, K1=K1, Kz=0.1, d=50.0)
    spin_rate = abs(B) * K1 / (m * J - B ** 2)
    ref = bp.integrate(scene, "odeint-rkf78", tol=1e-15, t_end=T_END, h=1e-3)["bodies"][0]
    print(f"far pass (Kz = 0.1, d = 50, t = {T_END:g}): error against odeint-rkf78 at tol 1e-15")
    print("| h | spin angle per step [rad] | " + " | ".join(f"{m} error | {m} force evals" for m in METHODS) + " |")
    print("|---|---|" + "---|---|" * len(METHODS))
    for h in STEPS:
        cells = []
        for m in METHODS:
            # The resolution check flags steps above pi of spin (docs/physics.md); here the run is
            # wanted as it is, to measure the error there, so no invariants and hence no flags.
            r = bp.integrate(scene, m, h=h, t_end=T_END, invariants=False)["bodies"][0]
            cells += [f"{distance(r, ref):.2e}", str(r["force_evals"])]
        print(f"| {h:g} | {spin_rate * h:.2f} | " + " | ".join(cells) + " |")


def far_share(binary):
    print("\nclose scene (Kz = 0.1, d = 0.05, t = 80), --tol: share of the delivered run's steps beyond r")
    print("| TOL | method, ds | steps | " + " | ".join(f"r > {r}" for r in RADII) + " |")
    print("|---|---|---|" + "---|" * len(RADII))
    with tempfile.TemporaryDirectory() as tmp:
        for tol in TOLS:
            out = os.path.join(tmp, "traj.csv")
            run = subprocess.run([binary, "simulate", "--tol", tol, "--Kz", "0.1", "--d", "0.05", "--t-end",
                                  str(T_END), "--out", out], check=True, capture_output=True, text=True)
            chosen = next(line.split()[0:2] for line in run.stdout.splitlines() if "method=" in line and "ds=" in line)
            d = np.genfromtxt(out, delimiter=",", names=True, comments="#")
            r = np.sqrt(d["Rx"] ** 2 + d["Ry"] ** 2 + d["Rz"] ** 2)
            n = len(r) - 1
            shares = [np.sum((r[1:] > r0) & (r[:-1] > r0)) / n for r0 in RADII]
            print(f"| {tol} | {chosen[0].split('=')[1]}, {float(chosen[1].split('=')[1]):.3g} | {n} | "
                  + " | ".join(f"{s:.2f}" for s in shares) + " |")


if __name__ == "__main__":
    resonances()
    far_share(sys.argv[1] if len(sys.argv) > 1 else "build/bin/bodypoint")
