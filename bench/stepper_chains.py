#!/usr/bin/env python3
"""Does a Stepper's estimate hold at every time it reaches? (issue #81, item 1)

Steppers made with a tolerance, as researchers put runs together: a span cut into 1, 7, 25 or 200 segments
(the estimate read after every segment), forwards and back in one Stepper, the same chain as two Steppers
with the first one's error carried into the second (carry_error), and a write w = -w at the closest approach
(apply). Each state is compared with lp-kl8 at h = 1e-3 landing on the same times (the reference's own
error, against h = 5e-4, is printed beside it). Prints every case and, over the states whose error is above
1e-12: the ratio estimate / error (median, 10th and 90th percentiles), the cases more than 3x low, the
companion's force evaluations over the run's.

Usage (from the repository, after the build; a few minutes on 2 cores):
    PYTHONPATH=build/python /usr/bin/python3 bench/stepper_chains.py [--quick]
"""
import argparse
import statistics
import sys

import numpy as np

import bodypoint as bp

# Errors below this are at the reference's and the rounding's level: no ratio is taken.
COMPARABLE = 1e-12
# An estimate more than this far below its error is counted as low.
LOW = 3.0


def relerr(state, ref):
    return max(np.linalg.norm(np.array(state["R"]) - ref["R"]) / np.linalg.norm(ref["R"]),
               np.linalg.norm(np.array(state["v"]) - ref["v"]) / np.linalg.norm(ref["v"]))


def scenes():
    return {
        "close": bp.thesis_scene(d=3, L=30),
        "spin": bp.thesis_scene(B=0.9, d=4, L=40, Kx=3),
        "attract": bp.Scene(centres=[{"position": [0, 0, 0], "A": 2.0}, {"position": [10, 3, 0], "A": -1.0}],
                            bodies=[{"m": 1, "B": 0.5, "J": 1.2, "R": [-20, 2, 0.5], "v": [3, 0, 0], "w": [0, 1, 2]}]),
        "bound": bp.Scene(centres=[{"position": [0, 0, 0], "A": -3.0}],
                          bodies=[{"m": 1, "B": 0.3, "J": 0.8, "R": [5, 0, 0], "v": [0, 0.7, 0.1], "w": [0.5, 0, 1]}]),
    }


def reference(scene, times, h=1e-3, flip_at=None):
    r = bp.Stepper(scene, "lp-kl8", h, invariants=False)
    out = []
    for t in times:
        if flip_at is not None and r.time < flip_at <= t:
            r.advance_to(flip_at)
            r.state = {"w": -np.array(r.state["w"])}
        r.advance_to(t)
        out.append({k: np.array(r.state[k]) for k in "Rv"})
    return out


class Tally:
    """The ratios estimate / error of the comparable states, the low cases, the companion's price."""

    def __init__(self):
        self.ratios, self.low, self.costs = [], [], []

    def record(self, case, est, err, ref_err, s):
        line = f"{case:44s} est {est:9.2e} err {err:9.2e} ref {ref_err:7.0e}"
        if err > COMPARABLE and err > 100 * ref_err:
            q = est / err
            self.ratios.append(q)
            if q < 1 / LOW:
                self.low.append(case)
                line += "  LOW"
        self.costs.append(s.error["force_evals"] / max(1, s.force_evals))
        print(line)
        sys.stdout.flush()

    def summary(self):
        q = sorted(self.ratios)
        print(f"\n{len(q)} states with an error above {COMPARABLE:g}: estimate / error median {statistics.median(q):.2f}, "
              f"10th percentile {q[len(q) // 10]:.2f}, 90th {q[(9 * len(q)) // 10]:.2f}; more than {LOW:g}x low: {len(self.low)}")
        for c in self.low:
            print("  low:", c)
        print(f"companion's force evaluations over the run's: median {statistics.median(self.costs):.2f}")


def segments(tally, name, scene, m, tol, T):
    """The span in 1, 7, 25 and 200 segments (shorter than a step: dense output), the estimate read after each (7)
    or at the end."""
    for nseg in (1, 7, 25, 200):
        times = list(np.linspace(0, T, nseg + 1)[1:])
        try:
            s = bp.Stepper(scene, m, tol=tol, t_end=T)
        except bp.Error as e:
            print(f"{name} {m} {tol:.0e}: refused ({str(e)[:70]})")
            return
        ref, ref2 = reference(scene, times), reference(scene, times, 5e-4)
        for t, rf, rf2 in zip(times, ref, ref2):
            s.advance_to(t)
            if t == times[-1] or nseg == 7:
                tally.record(f"{name} {m} {tol:.0e} {nseg} segments t={t:.3g}", s.error["estimate"],
                             relerr(s.state, rf), relerr({k: rf2[k] for k in "Rv"}, rf), s)


def out_and_back(tally, name, scene, m, tol, T):
    """Forwards and back in one stepper, and as two with the first one's error carried."""
    start = {k: np.array(scene.bodies[0][k]) for k in "Rv"}
    try:
        s = bp.Stepper(scene, m, tol=tol, t_end=T)
        s.advance_to(T)
        s.advance_to(0)
        tally.record(f"{name} {m} {tol:.0e} out and back", s.error["estimate"], relerr(s.state, start), 0, s)
        s1 = bp.Stepper(scene, m, tol=tol, t_end=T)
        s1.advance_to(T)
        body = dict(scene.bodies[0])
        body.update({k: s1.state[k] for k in "Rvw"})
        s2 = bp.Stepper(bp.Scene(centres=scene.centres, bodies=[body]), m, tol=tol, t_end=-T)
        s2.carry_error(s1.error)
        s2.advance_to(-T)
        tally.record(f"{name} {m} {tol:.0e} two steppers", s2.error["estimate"], relerr(s2.state, start), 0, s2)
    except bp.Error as e:
        print(f"{name} {m} {tol:.0e} back: refused ({str(e)[:70]})")


def flipped(tally, name, scene, m, tol, T):
    """A write w = -w half way (apply)."""
    try:
        s = bp.Stepper(scene, m, tol=tol, t_end=T)
    except bp.Error:
        return
    s.advance_to(T / 2)
    s.apply(lambda x: {"w": -np.array(x["w"])})
    s.advance_to(T)
    ref = reference(scene, [T], flip_at=T / 2)[0]
    ref2 = reference(scene, [T], 5e-4, flip_at=T / 2)[0]
    tally.record(f"{name} {m} {tol:.0e} w = -w at {T / 2:g}", s.error["estimate"], relerr(s.state, ref),
                 relerr({k: ref2[k] for k in "Rv"}, ref), s)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="auto and rk4 at tol 1e-6 and 1e-9 only")
    args = ap.parse_args()
    methods = ["auto", "rk4"] if args.quick else ["auto", "lp-y4", "rk4", "ttl-y4", "kep-y4"]
    tols = [1e-6, 1e-9] if args.quick else [1e-6, 1e-8, 1e-10]
    T = 25.0
    tally = Tally()
    for name, scene in scenes().items():
        for m in methods:
            for tol in tols:
                segments(tally, name, scene, m, tol, T)
                out_and_back(tally, name, scene, m, tol, T)
            for tol in tols:
                flipped(tally, name, scene, m, tol, T)
    tally.summary()


if __name__ == "__main__":
    main()
