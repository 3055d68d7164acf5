#!/usr/bin/env python3
"""The far field of a spinning body: what bounds the step there (docs/measurements.md, "Limits, measured").

Prints two tables:
1. The error of the exact splittings lp-y4 and lp-kl6 at fixed steps h on a pass that stays far from the
   centre (the thesis scene with Kz = 0.1, d = 50, t = 80), against the angle Omega_so h that one step
   turns the spin by. The error is smooth in h below pi per step and jumps at pi, 2 pi, 4 pi: a step
   longer than the spin period lands between resonances, and the error stops being the C h^p that
   Richardson's estimate assumes. Beside them the far-field collocation far-ip, whose step is set by
   the field's slow scale, at 0.5 to 100 rad of spin per step, and GSL's rk8pd at tolerances per step:
   error and force evaluations per radian of spin (the whole pass is beyond r = 50).
2. Where the steps go on the close scene (Kz = 0.1, d = 0.05, t = 80): the share of steps taken farther
   than r from the centre and the spin angle per step beyond r = 50, for the accuracy mode's delivered
   run and for the peers GSL rk8pd and Boost.Odeint rkf78 with their tolerance set to TOL.

Usage (from the repository, after the build):
    PYTHONPATH=build/python /usr/bin/python3 bench/far_field.py [build/bin/bodypoint] [--out-dir DIR]
With --out-dir, the two tables are also written (atomically) to DIR/far_field_resonances.csv and
DIR/far_field_share.csv, which paper/build.sh hands to the paper.
"""
import argparse
import csv
import os
import subprocess
import tempfile

import numpy as np
import bodypoint as bp

T_END = 80.0
STEPS = [0.1, 0.2, 0.3, 0.4, 0.45, 0.5, 0.6, 0.7, 0.8, 0.9, 0.916, 0.95, 1.0, 1.2, 1.4, 1.6, 1.83, 2.0, 2.5, 3.0]
METHODS = ["lp-y4", "lp-kl6"]
# far-ip's steps, as spin angles per step [rad]: across the splittings' resonances and far beyond.
FAR_METHOD = "far-ip"
FAR_ANGLES = [0.5, 1.0, 2.0, 3.14, 5.0, 6.28, 10.0, 12.57, 20.0, 30.0, 40.0, 55.0, 70.0, 100.0]
PEER_TOLS = [1e-6, 1e-8, 1e-10, 1e-12, 1e-14]
TOLS = ["1e-4", "1e-7", "1e-10"]
RADII = [5, 10, 20, 50]


def distance(b, ref):
    return max(np.linalg.norm(b["R"] - ref["R"]) / np.linalg.norm(ref["R"]),
               np.linalg.norm(b["v"] - ref["v"]) / np.linalg.norm(ref["v"]))


def write_csv(path, header, rows):
    """header and rows to path through a temporary file in the same folder, renamed into place."""
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)
    os.replace(tmp, path)


# The thesis's table 3.1, stated so that Omega_so is these scenes' (the far pass and the close scene).
M, B, J, K1 = 1.0, 0.7, 1.0, 5.0
SPIN_RATE = abs(B) * K1 / (M * J - B ** 2)


def resonances():
    scene = bp.thesis_scene(m=M, B=B, J=J, K1=K1, Kz=0.1, d=50.0)
    ref = bp.integrate(scene, "odeint-rkf78", tol=1e-15, t_end=T_END, h=1e-3)["bodies"][0]
    print(f"far pass (Kz = 0.1, d = 50, t = {T_END:g}): error against odeint-rkf78 at tol 1e-15")
    print("| h | spin angle per step [rad] | " + " | ".join(f"{m} error | {m} force evals" for m in METHODS) + " |")
    print("|---|---|" + "---|---|" * len(METHODS))
    rows = []
    for h in STEPS:
        cells = []
        for m in METHODS:
            # The resolution check flags steps above pi of spin (docs/physics.md); here the run is
            # wanted as it is, to measure the error there, so no invariants and hence no flags.
            r = bp.integrate(scene, m, h=h, t_end=T_END, invariants=False)["bodies"][0]
            err = distance(r, ref)
            cells += [f"{err:.2e}", str(r["force_evals"])]
            rows.append([m, repr(h), repr(SPIN_RATE * h), repr(err), r["force_evals"],
                         repr(r["force_evals"] / (SPIN_RATE * T_END))])
        print(f"| {h:g} | {SPIN_RATE * h:.2f} | " + " | ".join(cells) + " |")
    turned = SPIN_RATE * T_END
    print(f"\nthe same pass: {FAR_METHOD} at steps of tens of radians, and gsl-rk8pd at a tolerance per step")
    print("| method | step | spin angle per step [rad] | error | force evals | per radian |")
    print("|---|---|---|---|---|---|")
    for angle in FAR_ANGLES:
        n = max(1, round(turned / angle))
        h = T_END / n
        r = bp.integrate(scene, FAR_METHOD, h=h, t_end=T_END, invariants=False)["bodies"][0]
        if r["outcome"] != "ok":  # a step too long for what its points resolve: no numbers
            print(f"| {FAR_METHOD} | h = {h:.4g} | {SPIN_RATE * h:.3g} | not run: {r['reason']} | | |")
            continue
        err = distance(r, ref)
        print(f"| {FAR_METHOD} | h = {h:.4g} | {SPIN_RATE * h:.3g} | {err:.2e} | {r['force_evals']} | "
              f"{r['force_evals'] / turned:.2f} |")
        rows.append([FAR_METHOD, repr(h), repr(SPIN_RATE * h), repr(err), r["force_evals"],
                     repr(r["force_evals"] / turned)])
    if "gsl-rk8pd" in {m["name"] for m in bp.methods()}:  # GSL is optional in the build
        for tol in PEER_TOLS:
            r = bp.integrate(scene, "gsl-rk8pd", tol=tol, t_end=T_END, h=0.01, invariants=False)["bodies"][0]
            err = distance(r, ref)
            print(f"| gsl-rk8pd | tol = {tol:g} | {SPIN_RATE * T_END / r['steps']:.3g} | {err:.2e} | "
                  f"{r['force_evals']} | {r['force_evals'] / turned:.2f} |")
            rows.append(["gsl-rk8pd", "", repr(SPIN_RATE * T_END / r["steps"]), repr(err), r["force_evals"],
                         repr(r["force_evals"] / turned)])
    return rows


PEERS = ["gsl-rk8pd", "odeint-rkf78"]


def far_share(binary):
    """Where the steps go on the close scene: auto's delivered run at each TOL and the peers with their
    tolerance set to TOL. Everyone spends most steps far from the centre; there the spin angle per step
    (Omega_so dt) says how finely each resolves the helix."""
    print("\nclose scene (Kz = 0.1, d = 0.05, t = 80): where the steps go; auto's delivered run (--tol) and the"
          " peers at tolerance TOL")
    print("| TOL | method | steps | force evals (delivered run) | " + " | ".join(f"r > {r}" for r in RADII)
          + " | spin angle per step beyond r = 50 [rad] |")
    print("|---|---|---|---|" + "---|" * len(RADII) + "---|")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "traj.csv")
        for tol in TOLS:
            for method in ["auto"] + PEERS:
                # Where the delivered run's steps go: no companion run for an error estimate, and a peer
                # at a loose tolerance reports its steps whatever its error.
                args = [binary, "simulate", "--tol", tol, "--Kz", "0.1", "--d", "0.05", "--t-end", str(T_END),
                        "--out", out, "--no-error-estimate"]
                if method != "auto":
                    args += ["--method", method]
                run = subprocess.run(args, check=True, capture_output=True, text=True)
                chosen, label = method, method
                if method == "auto":
                    fields = next(line.split()[0:2] for line in run.stdout.splitlines()
                                  if "method=" in line and "ds=" in line)
                    chosen = fields[0].split("=")[1]
                    label = f"auto: {chosen}, ds {float(fields[1].split('=')[1]):.3g}"
                evals = next(line.split("=")[1].split(",")[0].strip() for line in run.stdout.splitlines()
                             if line.strip().startswith("force evaluations ="))
                d = np.genfromtxt(out, delimiter=",", names=True, comments="#")
                r = np.sqrt(d["Rx"] ** 2 + d["Ry"] ** 2 + d["Rz"] ** 2)
                n = len(r) - 1
                beyond = [(r[1:] > r0) & (r[:-1] > r0) for r0 in RADII]
                angle = SPIN_RATE * np.mean(np.diff(d["t"])[beyond[-1]])
                shares = [np.sum(b) / n for b in beyond]
                print(f"| {tol} | {label} | {n} | {evals} | " + " | ".join(f"{x:.2f}" for x in shares)
                      + f" | {angle:.2f} |")
                rows.append([tol, method, chosen, n, evals, *[repr(x) for x in shares], repr(angle)])
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binary", nargs="?", default="build/bin/bodypoint")
    parser.add_argument("--out-dir", help="also write far_field_resonances.csv and far_field_share.csv here")
    args = parser.parse_args()
    res = resonances()
    share = far_share(args.binary)
    if args.out_dir:
        write_csv(os.path.join(args.out_dir, "far_field_resonances.csv"),
                  ["method", "h", "spin_angle", "err", "force_evals", "evals_per_radian"], res)
        write_csv(os.path.join(args.out_dir, "far_field_share.csv"),
                  ["tol", "who", "method", "steps", "force_evals"] + [f"share_beyond_{r}" for r in RADII]
                  + [f"spin_angle_beyond_{RADII[-1]}"], share)


if __name__ == "__main__":
    main()
