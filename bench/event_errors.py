"""Do a located event's stated errors cover its distance from the truth? (issue #81 item 2)

Runs `simulate --scattering --json` on a few encounters (the thesis's, a stronger coupling, a close pass, a weaker
spin, an attracting centre) with the accuracy mode at three TOLs and four methods at fixed steps, and compares
each closest approach's r_min and t_min with lp-kl8 at h = 0.0025 (whose own error is ~1e-14 there). Prints each
case where a stated error is more than 3x below its error, then: how many quantities had a stated error, the
ratios stated error / error (of errors above 1e-13 of the value), and the events' force evaluations as a share
of the whole call's.

    /usr/bin/python3 bench/event_errors.py build/bin/bodypoint
"""
import json
import statistics
import subprocess
import sys

SCENES = [[], ["--B", "0.9", "--d", "4"], ["--d", "3", "--Kz", "1"], ["--B", "0.3", "--d", "6", "--K1", "4"],
          ["--A", "2", "--d", "8", "--B", "0.5"]]
CONFIGS = [["--tol", "1e-6"], ["--tol", "1e-8"], ["--tol", "1e-9"], ["--method", "lp-y4", "--h", "0.01"],
           ["--method", "logh-kl6", "--h", "0.05"], ["--method", "lp-kl8", "--h", "0.02"], ["--method", "rk4", "--h", "0.002"]]
REFERENCE = ["--method", "lp-kl8", "--h", "0.0025", "--no-error-estimate"]
# Errors below this share of the value are the reference's and the rounding's: no ratio is taken.
COMPARABLE = 1e-13
LOW = 3.0


def scattering(binary, args):
    out = subprocess.run([binary, "simulate", "--scattering", "--json", *args], capture_output=True, text=True).stdout
    return json.loads(out) if out else {}


def compare(binary, scene, ref, tally):
    for config in CONFIGS:
        d = scattering(binary, config + scene)
        if "scattering" not in d:
            print("no encounter:", " ".join(scene + config), d.get("reason", "")[:80])
            continue
        for q in ("r_min", "t_min"):
            tally["quantities"] += 1
            err, est = abs(d["scattering"][q] - ref[q]), d["scattering"].get(q + "_error")
            if est is None or est != est:
                continue
            tally["known"] += 1
            if err > COMPARABLE * abs(ref[q]):
                tally["ratios"].append(est / err)
            if est < err / LOW:
                print(f"low: {' '.join(scene + config)} {q}: stated {est:.2e}, off by {err:.2e}")
        tally["share"].append(d["event_force_evals"] / max(1, d["total_force_evals"]))


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else "build/bin/bodypoint"
    tally = {"quantities": 0, "known": 0, "ratios": [], "share": []}
    for scene in SCENES:
        ref = scattering(binary, REFERENCE + scene).get("scattering")
        if ref:
            compare(binary, scene, ref, tally)
    q = sorted(tally["ratios"])
    print(f"{tally['known']} of {tally['quantities']} quantities with a stated error; stated / error over {len(q)}: "
          f"min {q[0]:.2f}, median {statistics.median(q):.2f}, max {q[-1]:.2f}, more than {LOW:g}x low "
          f"{sum(x < 1 / LOW for x in q)}")
    print(f"events' force evaluations over the whole call's: median {statistics.median(tally['share']):.2f}, "
          f"max {max(tally['share']):.2f}")


if __name__ == "__main__":
    main()
