#!/usr/bin/env python3
"""Do a run's flags and its error estimate tell right answers from wrong ones? (issue #40)

A step ladder of every method over thirteen scenes (two attracting and two several-centre scenes
added for issue #56): each run is made as a user makes it (`bodypoint
simulate --json`, the default bounds: energy error and estimated error 1e-2) and its final state is
compared with a reference (Boost.Odeint rkf78 in long double at tolerance 1e-16, `--reference`, one per
scene). A run refused by a flag is made again with the bounds lifted, to know its error. Prints:
  - exit 0 with a true error above 10 % and no estimate showing it (the estimate below 10 %);
  - right answers refused: a flag refused a run whose true error is below the flag's bound (1e-2);
  - the estimate's ratio to the true error (runs whose error is above the round-off level);
  - what the estimate costs: its force evaluations over the delivered run's;
  - runs with no estimate, and the methods' refusals of scenes they do not take (not flags).

Usage (from the repository, after the build; a few minutes on 2 cores):
    /usr/bin/python3 bench/estimate_ladder.py [build/bin/bodypoint] [--threads 2] [--csv out.csv] [--unseen]
"""
import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

# The flags' bound (bodypoint's kDefaultMaxError and kDefaultMaxEnergyError).
BOUND = 1e-2
# The threshold of a wrong answer.
WRONG = 0.1
# Below this the reference's own error is of the size of the error itself: on the bound orbit (t = 300)
# kep-y8d at h = 0.05 and 0.025 and kep-kl8 at h = 0.02 agree to 1e-13 and are all 3.5e-12 from it.
COMPARABLE = 1e-10
# Above this a state is lost whatever its estimate says (diverged runs reach 1e120): no ratio is taken.
LOST = 1.0
# Estimates within this factor of the true error count as honest.
FACTOR = 3.0
STEPS = ["1", "0.5", "0.2", "0.1", "0.05", "0.02", "0.01"]
TOLS = ["1e-3", "1e-5", "1e-7", "1e-9"]

# The two repelling centres of scenes/two-centres.toml.
CENTRES = """[[centre]]
position = [0.0, 0.0, 0.0]
A = -2.0
[[centre]]
position = [40.0, 6.0, 0.0]
A = -1.0
"""
def material_body(R, v):
    """A material point (B = 0) started from R with velocity v, as scene-file text."""
    return f"""[[body]]
name = "material"
m = 1.0
B = 0.0
J = 1.0
R = {R}
v = {v}
w = [0.0, 0.0, 0.0]
"""


TWO_CENTRES = CENTRES + material_body([-150.0, 3.0, 0.0], [5.0, 0.0, 0.0])


# Several centres with the thesis's spinning body: two repelling, then one attracting beyond them (the
# named scenes two-centres and three-centres of lib/core/model/bodypoint/scenes.hpp).
SPINNING_BODY = """[[body]]
name = "spinning"
m = 1.0
B = 0.7
J = 1.0
d = 10.0
L = 200.0
K1 = 5.0
Kx = 2.0
Kz = 5.0
"""
TWO_CENTRES_SPIN = CENTRES + SPINNING_BODY
THREE_CENTRES = CENTRES + """[[centre]]
position = [80.0, -8.0, 0.0]
A = 1.5
""" + SPINNING_BODY


def bound_orbit(B):
    return f"""[[centre]]
position = [0.0, 0.0, 0.0]
A = 1.0
[[body]]
name = "bound"
m = 1.0
B = {B}
J = 1.0
R = [1.0, 0.0, 0.0]
v = [0.0, 1.2, 0.0]
w = [0.0, 0.0, 1.0]
"""


# Scenes the estimate was not tuned on (`--unseen`, issue #81): a tilted spin, a slow close pass, a spinning
# body about an attracting centre, a far pass, and a material body through three centres of mixed sign.
MIXED_CENTRES = """[[centre]]
position = [0.0, 0.0, 0.0]
A = -1.5
[[centre]]
position = [25.0, -4.0, 0.0]
A = 1.0
[[centre]]
position = [50.0, 5.0, 2.0]
A = -0.5
""" + material_body([-60.0, 1.5, 0.3], [4.0, 0.0, 0.0])


def unseen_scenes(folder):
    path = os.path.join(folder, "mixed-centres.toml")
    with open(path, "w") as f:
        f.write(MIXED_CENTRES)
    return [
        ("tilted-spin", ["--B", "0.5", "--d", "6", "--Kx", "4", "--Kz", "2"], "30"),
        ("slow-close", ["--d", "2", "--K1", "2"], "60"),
        ("attracting-spin", ["--A", "1.5", "--B", "0.8", "--d", "4"], "60"),
        ("far-pass", ["--d", "30", "--L", "100"], "40"),
        ("mixed-centres", ["--scene", path], "40"),
    ]


def scenes(folder):
    files = {}
    for name, text in [("two-centres", TWO_CENTRES), ("bound", bound_orbit(0.0)), ("bound-spin", bound_orbit(0.7)),
                       ("two-centres-spin", TWO_CENTRES_SPIN), ("three-centres", THREE_CENTRES)]:
        path = os.path.join(folder, name + ".toml")
        with open(path, "w") as f:
            f.write(text)
        files[name] = path
    return [
        ("table-3.1", [], "20"),
        ("material", ["--B", "0"], "20"),
        ("close-pass", ["--d", "1"], "40"),
        ("attracting", ["--A", "2", "--d", "3"], "80"),
        ("head-on", ["--d", "0.05", "--Kz", "0.1"], "80"),
        ("strong-spin", ["--B", "0.9", "--d", "3"], "40"),
        ("two-centres", ["--scene", files["two-centres"]], "60"),
        ("bound-orbit", ["--scene", files["bound"]], "300"),
        ("bound-spin", ["--scene", files["bound-spin"]], "300"),
        # Two more attracting and two several-centre scenes (issue #56).
        ("attracting-material", ["--A", "2", "--B", "0", "--d", "3"], "80"),
        ("attracting-close", ["--A", "1", "--d", "1.5"], "80"),
        ("two-centres-spin", ["--scene", files["two-centres-spin"]], "60"),
        ("three-centres", ["--scene", files["three-centres"]], "60"),
    ]


def simulate(binary, args):
    r = subprocess.run([binary, "simulate", "--json", "--quiet", *args], capture_output=True, text=True)
    return r.returncode, (json.loads(r.stdout) if r.returncode == 0 else None), r.stderr.strip()


def distance(a, b):
    def rel(x, y):
        n = math.sqrt(sum(c * c for c in y))
        d = math.hypot(*(p - q for p, q in zip(x, y)))
        return d / n if n > 0 else d
    return max(rel(a["R"], b["R_ref"]), rel(a["v"], b["v_ref"]))


def references(binary, scene_list):
    """Each scene's reference final state (R_ref, v_ref: `--reference`), by scene name."""
    refs = {}
    for scene, args, t_end in scene_list:
        code, out, err = simulate(binary, [*args, "--t-end", t_end, "--method", "lp-y4", "--h", "0.01", "--reference",
                                           "--max-error", "inf", "--max-energy-error", "inf"])
        if code != 0:
            sys.exit(f"reference of {scene}: {err}")
        refs[scene] = out
    return refs


def one(binary, job):
    scene, args, t_end, method, step = job
    base = [*args, "--t-end", t_end, "--method", method["method"]]
    base += ["--tol", step] if method["advance"] == "controlled" else ["--h", step]
    code, out, err = simulate(binary, base)
    row = {"scene": scene, "method": method["method"], "step": step, "exit": code, "reason": err}
    if out is not None:  # what the delivered run and its estimate cost
        row["force_evals"], row["estimate_force_evals"] = out["force_evals"], out["estimate_force_evals"]
    # Without invariants no flag is raised: the state and its estimate come out whatever the flags said.
    lifted = out if code == 0 else simulate(binary, base + ["--no-invariants", "--max-error", "inf",
                                                           "--max-energy-error", "inf"])[1]
    if lifted is not None:
        row["R"], row["v"] = lifted["R"], lifted["v"]
        row["estimate"] = lifted["err_estimate"]
        row["basis"] = lifted.get("err_basis", "")
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary", nargs="?", default="build/bin/bodypoint")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--csv")
    ap.add_argument("--unseen", action="store_true", help="five scenes the estimate was not tuned on instead")
    a = ap.parse_args()
    listing = subprocess.run([a.binary, "methods", "--csv"], capture_output=True, text=True, check=True).stdout
    methods = list(csv.DictReader(listing.splitlines()))
    with tempfile.TemporaryDirectory() as folder:
        scene_list = unseen_scenes(folder) if a.unseen else scenes(folder)
        refs = references(a.binary, scene_list)
        jobs = [(s, args, t, m, step) for s, args, t in scene_list for m in methods
                for step in (TOLS if m["advance"] == "controlled" else STEPS)]
        with ThreadPoolExecutor(a.threads) as pool:
            rows = list(pool.map(lambda j: one(a.binary, j), jobs))
    wrong_ok, right_refused, no_estimate, not_run, between = [], [], 0, 0, 0
    ratios = {"delivered (exit 0)": [], "refused (made again without flags)": []}
    for r in rows:
        if "R" not in r:
            not_run += 1  # the method refuses the scene, or its state is not finite
            continue
        r["error"] = distance(r, refs[r["scene"]])
        est = r["estimate"]
        if est is None:
            no_estimate += 1
        if r["exit"] == 0:
            if r["error"] > WRONG and (est is None or est < WRONG):
                wrong_ok.append(r)
            elif r["error"] > BOUND:
                between += 1
        elif r["error"] < BOUND:
            right_refused.append(r)
        if est is not None and COMPARABLE < r["error"] <= LOST:
            ratios["delivered (exit 0)" if r["exit"] == 0 else "refused (made again without flags)"].append(
                (est / r["error"], r))
    print(f"{len(rows)} runs ({len(methods)} methods, {len(scene_list)} scenes); {not_run} not run (the method "
          f"refuses the scene) or not finite; {no_estimate} without an estimate")
    print(f"exit 0 with error > {WRONG:g} and no estimate showing it: {len(wrong_ok)}")
    for r in wrong_ok[:10]:
        print(f"   {r['scene']} {r['method']} {r['step']}: error {r['error']:.3g}, estimate {r['estimate']}")
    print(f"exit 0 with error between {BOUND:g} and {WRONG:g}: {between}")
    print(f"refused with error below the bound {BOUND:g}: {len(right_refused)}")
    for r in right_refused[:10]:
        print(f"   {r['scene']} {r['method']} {r['step']}: error {r['error']:.3g}, estimate {r['estimate']}: {r['reason'][:150]}")
    for label, pairs in ratios.items():
        print_ratios(label, pairs)
    print_cost(rows)
    if a.csv:
        write_rows(a.csv, rows)


def print_ratios(label, pairs):
    """Estimate over error of the runs `pairs` ((ratio, run)): quantiles, within FACTOR, the lowest."""
    x = [p[0] for p in pairs]
    if len(x) < 2:
        return
    q = statistics.quantiles(x, n=20)
    within = sum(1 for v in x if 1 / FACTOR <= v <= FACTOR)
    low = sorted((p for p in pairs if p[0] < 1 / FACTOR), key=lambda p: p[0])
    print(f"estimate / error, {label}, {len(x)} runs with error in ({COMPARABLE:g}, {LOST:g}]: median {statistics.median(x):.3g}, "
          f"5 % {q[0]:.3g}, 95 % {q[-1]:.3g}, min {min(x):.3g}, max {max(x):.3g}; within {FACTOR:g}x: "
          f"{within} ({100 * within / len(x):.1f} %), more than {FACTOR:g}x low: {len(low)}")
    for v, r in low[:8]:
        print(f"   {r['scene']} {r['method']} {r['step']}: error {r['error']:.3g}, estimate {r['estimate']:.3g}")


def print_cost(rows):
    """The estimate's price on the delivered runs: its force evaluations over the run's, in total and per run."""
    paid = [(r["estimate_force_evals"], r["force_evals"]) for r in rows
            if r["exit"] == 0 and r.get("force_evals") and r.get("estimate_force_evals") is not None]
    if not paid:
        return
    total = sum(e for e, _ in paid) / sum(n for _, n in paid)
    per_run = statistics.median(e / n for e, n in paid)
    print(f"estimate's force evaluations over the run's, {len(paid)} delivered runs: {total:.3f} in total, median {per_run:.3f}")


def write_rows(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "method", "step", "exit", "error", "estimate", "force_evals", "estimate_force_evals", "reason", "basis"])
        for r in rows:
            w.writerow([r["scene"], r["method"], r["step"], r["exit"], r.get("error", ""), r.get("estimate", ""),
                        r.get("force_evals", ""), r.get("estimate_force_evals", ""), r["reason"], r.get("basis", "")])


if __name__ == "__main__":
    main()
