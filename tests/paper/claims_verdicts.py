#!/usr/bin/env python3
"""The paper's table of claims gives a cost claim a verdict only from counted times: a timing study
whose times were all flagged (a contended machine, as under a parallel test run) reads "untimed (...)"
naming the flags, which check_paper accepts; a study that did not run leaves "--", which it refuses.

usage: claims_verdicts.py SOURCE_DIR"""
import os
import sys
import tempfile

sys.path.insert(0, os.path.join(sys.argv[1], "paper"))
import check_paper  # noqa: E402
from macros import chapter4, common  # noqa: E402

HEADER = "n,method,median_s,min_s,max_s,cpu_s,spread,repeats,flag,force_evals\n"


def timing_csv(directory, flag_of, label="model"):
    """A timing study of the seven thesis methods at three lengths, each time flagged by flag_of(method),
    under the names the column's study gives them (as published, AB4 is "ab4-thesis")."""
    with open(os.path.join(directory, common.TIMING_CSV[label]), "w") as f:
        f.write("# bodypoint timing (test)\n" + HEADER)
        for m in (common.csv_method(label, m) for m in common.THESIS_SEVEN):
            for n in (20000, 40000, 80000):
                f.write(f'{n},{m},{n * 1e-7},{n * 1e-7},{n * 1e-7},{n * 1e-7},0.01,5,"{flag_of(m)}",{n}\n')


def verdict_accepted(cell):
    with tempfile.TemporaryDirectory() as build:
        os.makedirs(os.path.join(build, "generated"))
        with open(os.path.join(build, "generated", "tab_claims.tex"), "w") as f:
            f.write(f"14 & a claim & 4.6 & yes (test) & {cell} \\\\\n")
        return not check_paper.claims_without_verdict(build)


def main():
    failures = []
    with tempfile.TemporaryDirectory() as res:
        timing_csv(res, lambda m: "")
        ns = common.timing_ns(res)
        if sorted(ns) != sorted(common.THESIS_SEVEN) or abs(ns["rk4"] - 100.0) > 1e-6:
            failures.append(f"unflagged times: ns per step {ns}, expected 100 for each of the seven")
        if common.untimed(res, "timing.csv", []):
            failures.append("a method with a time is reported untimed")

        contended = "contended: wall 31 % above CPU; spread 22 %"
        timing_csv(res, lambda m: contended if m in ("rk4", "thesis-y6") else "")
        ns = common.timing_ns(res)
        if "rk4" in ns or "thesis-y6" in ns:
            failures.append(f"flagged times were fitted: {sorted(ns)}")
        why = common.untimed(res, "timing.csv", [m for m in common.THESIS_SEVEN if m not in ns])
        if why != "times flagged for y6, rk4: contended, spread":
            failures.append(f"untimed reason: {why!r}")
        if not verdict_accepted(f"untimed ({why})"):
            failures.append("check_paper refuses an untimed verdict")

        # The published study names AB4 "ab4-thesis": every time flagged (a busy machine) must still give
        # the seven an "untimed" reason, not "--" (the quick build failed so under ctest -j2).
        timing_csv(res, lambda m: contended, "code")
        ns = common.seven_ns(res, "code")
        why = common.seven_untimed(res, "code", ns)
        if ns or "ab4-thesis" not in why or not why.startswith("times flagged for euler"):
            failures.append(f"published study all flagged: ns {sorted(ns)}, untimed reason {why!r}")
        timing_csv(res, lambda m: "", "code")
        ns = common.seven_ns(res, "code")
        if sorted(ns) != sorted(common.THESIS_SEVEN) or common.seven_untimed(res, "code", ns):
            failures.append(f"published study unflagged: ns per step {ns}, expected the seven (ab4 as ab4)")

        os.remove(os.path.join(res, "timing.csv"))
        if common.untimed(res, "timing.csv", ["rk4"]):
            failures.append("a study that did not run is reported untimed")
    if verdict_accepted("--"):
        failures.append("check_paper accepts a claim without a verdict")
    # A run is diverged where its energy deviation exceeds one, as the paper defines it, even with a finite
    # deviation (RK4 at h = 0.5: dE = 6e34): it is n/a for a comparison, not a ranked number.
    rows = [{"h": "0.5", "method": m, "dev": "0.3", "max_rel_dE": "6e34" if m in common.STANDARD else "0.01"}
            for m in common.THESIS_SEVEN]
    d = chapter4.deviations(rows, "h", "dev")[0.5]
    if not common.standard_diverged(d) or d["thesis-y6"] != 0.3:
        failures.append(f"a run with dE above 1 is not diverged: {d}")
    rows = [dict(r, max_rel_dE="nan") for r in rows]  # the thesis code's force law: E is no integral
    if common.standard_diverged(chapter4.deviations(rows, "h", "dev")[0.5]):
        failures.append("an energy deviation of NaN (no integral) made the runs diverged")
    for f in failures:
        print(f"claims_verdicts: {f}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
