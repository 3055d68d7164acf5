"""Section 'Chapter 4 reproduced': the sweeps, the thesis's claims tested, the harness, the Java agreement, the
timings of the seven methods.
"""

import math
import os
import re
import statistics

from macros.common import (
    NA, ORDER_WINDOW, STANDARD, THESIS_SEVEN, TIE, TIE_DIGITS, TIMING_CSV, below, camel, count, csv_method,
    finite, num, read_csv, sci, seven_ns, seven_untimed, slope, tied, tt,
)


def sweep_stats(rows, param, prefix, M, methods_for_wins):
    values = sorted({num(r[param]) for r in rows})
    M.add(f"N{prefix}{camel(param)}Values", count(len(values)))
    M.add(f"{prefix}{camel(param)}Min", sci(values[0]))
    M.add(f"{prefix}{camel(param)}Max", sci(values[-1]))
    per = {}
    for r in rows:
        per.setdefault(r["method"], []).append(num(r["max_rel_dE"]))
    for m, vs in per.items():
        finite = [v for v in vs if math.isfinite(v)]
        M.add(f"Med{prefix}{camel(param)}{camel(m)}", sci(statistics.median(finite)) if finite else "n/a")
    for label, pool in methods_for_wins.items():
        wins = {m: 0 for m in pool}
        for v in values:
            cands = [(num(r["max_rel_dE"]), r["method"]) for r in rows if num(r[param]) == v and r["method"] in pool]
            cands = [c for c in cands if math.isfinite(c[0])]
            if cands:
                wins[min(cands)[1]] += 1
        top = max(wins, key=lambda m: wins[m])
        M.add(f"Top{prefix}{label}{camel(param)}", tt(top), math_mode=False)
        M.add(f"Top{prefix}{label}{camel(param)}Count", count(wins[top]))
        rk = wins.get("rk4", 0) + wins.get("ab4", 0)
        if label == "Seven":
            M.add(f"RkAbWins{prefix}{camel(param)}", count(rk))
    thesis = [v for m, vs in per.items() if m.startswith("thesis-") for v in vs if math.isfinite(v)]
    M.add(f"ThesisFamilyMed{prefix}{camel(param)}", sci(statistics.median(thesis)))
    lp = [statistics.median(vs) for m, vs in per.items() if m.startswith("lp-") and m != "lp-euler"]
    if lp:
        M.add(f"LpMedLow{prefix}{camel(param)}", sci(min(lp)))
        M.add(f"LpMedHigh{prefix}{camel(param)}", sci(max(lp)))


SYMPLECTIC = [m for m in THESIS_SEVEN if m.startswith("thesis-")]


# "Near the centre" in the L sweep: a start no farther along x than the impact distance (d = 50).
NEAR_L = 50


# The h sweep's coarse steps (thesis fig. 4.5) and small steps (fig. 4.6-4.7: the harness's h <= 1e-4).
COARSE_H, SMALL_H = 1e-2, 1e-4


# "Well conserved": |K2|^2 deviates by less than this (relative) in every run at the thesis's h = 1e-4.
WELL_CONSERVED = 1e-3


# A run whose relative energy deviation exceeds this is diverged, as the paper defines it (sec. flags,
# bodypoint's kDivergedEnergy): RK4 at h = 0.5 with dE = 6e34 is not a finite deviation to rank.
DIVERGED_ENERGY = 1.0


def deviations(rows, param, column):
    """{value: {method: deviation}} for the thesis's seven; a diverged run (a non-finite deviation, or an
    energy deviation above DIVERGED_ENERGY) counts as infinite."""
    out = {}
    for r in rows:
        if r["method"] in THESIS_SEVEN:
            v = num(r[column])
            energy = num(r.get("max_rel_dE"))  # NaN where E is not an integral (the thesis code's force law)
            diverged = not math.isfinite(v) or energy > DIVERGED_ENERGY
            out.setdefault(num(r[param]), {})[r["method"]] = float("inf") if diverged else v
    return out


def tally(points, test, where=lambda v: True):
    """(k, n, tied, na): of the points (value in `where`) at which `test(deviations)` decides, how many
    hold; how many were ties (TIE) and how many are not applicable (NA: RK4 and AB4 diverge there too,
    so no comparison with them means anything)."""
    chosen = [d for v, d in points.items() if where(v) and all(m in d for m in THESIS_SEVEN)]
    out = [test(d) for d in chosen]
    decided = [x for x in out if x not in (TIE, NA)]
    return sum(1 for x in decided if x), len(decided), out.count(TIE), out.count(NA)


def ranked(m, pool, pick):
    """Whether m is pool's extreme by `pick` (min or max); TIE when the runner-up agrees with it."""
    def test(d):
        order = sorted(pool, key=lambda x: d[x], reverse=pick is max)
        if tied(d[order[0]], d[order[1]]):
            return TIE
        return order[0] == m
    return test


def smallest(m, pool):
    return ranked(m, pool, min)


def largest(m, pool):
    return ranked(m, pool, max)


def verdict(k, n, ties=0, na=0):
    notes = (f"; {ties} tied" if ties else "") + (f"; {na} n/a" if na else "")
    if n == 0:  # no point decides: all tied, or not applicable
        if ties or na:
            return f"{'tied' if ties >= na else 'n/a'} ({ties} tied, {na} n/a)"
        return "--"
    word = "yes" if k == n else "no" if k == 0 else "partly"
    return f"{word} ({k}/{n}{notes})"


# Deviations below this are compared by their absolute difference: two integrations that round
# differently (Java's and C++'s operation order) differ there by the accumulated roundings of 1e5..1e6
# steps, about 1e-15 absolute, which is a large fraction of a deviation of 1e-10.
ROUNDOFF_DEVIATION = 1e-8


def java_agreement(M):
    """How far the published sweeps are from the thesis's own Java solvers (paper/java/compare.sh writes
    the committed paper/java_agreement.csv; it needs the thesis's repository, so the build only reads it).
    Runs that bodypoint flags (diverged, unresolved: no number to agree with) are counted, not compared."""
    rows, header = read_csv(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "java_agreement.csv"))
    made = re.search(r"bodypoint (\S+) against .*\((\S+) ([0-9a-f]{7})[0-9a-f]*\)", header[0])
    M.add("JavaMadeAt", f"\\texttt{{{made.group(1)}}}" if made else "unknown", math_mode=False)
    M.add("JavaThesisCommit", f"\\texttt{{{made.group(3)}}}" if made else "unknown", math_mode=False)
    ok = [r for r in rows if r["outcome"] == "ok"]
    M.add("JavaRuns", count(len(rows)))
    M.add("JavaRunsOk", count(len(ok)))
    for ours, theirs, name in [("max_rel_dE", "java_max_rel_dE", "Energy"), ("max_rel_dK2sq", "java_max_rel_dK2sq", "Ktwo")]:
        pairs = [(num(r[ours]), num(r[theirs])) for r in ok]
        above = [(a, b) for a, b in pairs if min(a, b) > ROUNDOFF_DEVIATION]
        M.add(f"JavaAgree{name}", sci(max(abs(a - b) / b for a, b in above)))
        M.add(f"JavaAgree{name}Runs", count(len(above)))
        small = [abs(a - b) for a, b in pairs if min(a, b) <= ROUNDOFF_DEVIATION]
        M.add(f"JavaRoundoff{name}", count(len(small)))
        M.add(f"JavaAbs{name}", sci(max(small)) if small else "n/a")
    M.add("JavaAgreeR", sci(max(num(r["rel_diff_R"]) for r in ok)))
    M.add("JavaAgreeRMedian", sci(statistics.median(num(r["rel_diff_R"]) for r in ok)))


def harness(res, M):
    """The thesis code harnesses' start in the thesis's terms, as `study --name published` wrote it."""
    _, header = read_csv(os.path.join(res, "published_d_sweep.csv"))
    fixed = next(line for line in header if line.startswith("# fixed:"))
    for key in ["K1", "Kx", "Kz"]:
        value = float(re.search(rf" {key}=(\S+)", fixed).group(1))
        M.add(f"Harness{camel(key)}", f"{value:.5g}")


class ClaimTests:
    """The tests behind table~\\ref{tab:claims}: each takes a label ("code": the sweeps as published, the
    code's harnesses, force law, slip and loop; "model": the corrected model, table 3.1) and returns the
    verdict printed in that column."""

    def __init__(self, res, M):
        self.res, self.M = res, M
        self.data = {}
        for label, prefix in [("code", "published_"), ("model", "")]:
            for param in ["d", "L", "h", "Kx"]:
                rows, _ = read_csv(os.path.join(res, f"{prefix}{param}_sweep.csv"))
                for column in ["max_rel_dE", "max_rel_dK2sq"]:
                    self.data[label, param, column] = deviations(rows, param, column)
        # Costs under each column's own law: the timing study on table 3.1 (corrected) and on the harness's
        # scene under the code's force law (published_timing.csv).
        self.ns_by = {label: seven_ns(res, label) for label in TIMING_CSV}
        evals, _ = read_csv(os.path.join(res, "force_evals.csv"))
        self.measured = {r["method"]: num(r["measured_per_step"]) for r in evals}

    def sweep(self, param, column, test, where=lambda v: True):
        return lambda label: verdict(*tally(self.data[label, param, column], test, where))

    def near_far(self, label):
        pts = self.data[label, "d", "max_rel_dE"]
        lo, hi = min(pts), max(pts)
        ratios = [pts[lo][m] / pts[hi][m] for m in THESIS_SEVEN]
        ties = sum(1 for m in THESIS_SEVEN if tied(pts[lo][m], pts[hi][m]))
        k = sum(1 for m, r in zip(THESIS_SEVEN, ratios) if r > 1 and not tied(pts[lo][m], pts[hi][m]))
        return f"{verdict(k, len(THESIS_SEVEN) - ties, ties)[:-1]}; ratio ${sci(min(ratios))}$ to ${sci(max(ratios))}$)"

    def y6_overall(self, label):
        total = [0, 0, 0, 0]
        for param, where in [("d", lambda v: True), ("L", lambda v: True), ("h", lambda v: v <= SMALL_H)]:
            total = [x + y for x, y in zip(total, tally(self.data[label, param, "max_rel_dE"],
                                                        smallest("thesis-y6", SYMPLECTIC), where))]
        return verdict(*total)

    def well_conserved(self, label):
        worst = max(d[m] for v, d in self.data[label, "h", "max_rel_dK2sq"].items()
                    if abs(v - SMALL_H) < 1e-12 * SMALL_H for m in THESIS_SEVEN)
        return f"{'yes' if worst < WELL_CONSERVED else 'no'} (max ${sci(worst)}$)"

    def not_timed(self, label):
        """The verdict of a cost claim whose methods lack a time: "untimed (...)" naming the flags that
        left a method without two counted times (a contended machine), or "--" when the study did not run."""
        why = seven_untimed(self.res, label, self.ns_by[label])
        if why:
            self.M.ledger.lost("the cost claims of table~\\ref{tab:claims} " + ("as published" if label == "code" else
                                                                                 "on the corrected model"), why)
        return f"untimed ({why})" if why else "--"

    def cost(self, test, text):
        def claim(label):
            ns = self.ns_by[label]
            if not all(m in ns for m in THESIS_SEVEN):
                return self.not_timed(label)
            return f"{'yes' if test(ns) else 'no'} ({text(ns)})"
        return claim

    def euler_cheap_and_better(self, label):
        ns = self.ns_by[label]
        k, n, ties, na = tally(self.data[label, "d", "max_rel_dE"], below(["thesis-euler"], STANDARD))
        if not all(m in ns for m in THESIS_SEVEN):
            return self.not_timed(label)
        if n == 0:
            return "--"
        holds = ns["thesis-euler"] < min(ns["rk4"], ns["ab4"]) and k == n
        return (f"{'yes' if holds else 'no'} ({ns_of(ns, 'thesis-euler')} ns against {ns_of(ns, 'rk4')}, "
                f"{ns_of(ns, 'ab4')}; energy {verdict(k, n, ties, na).split(' ', 1)[1][1:-1]})")

    def table41(self, label):
        # As published: the thesis's code's AB4 (ab4-thesis) re-evaluates the four past right-hand sides
        # every step; corrected: bodypoint's (odeint's) keeps them. Both counted over a run.
        m = csv_method(label, "ab4")
        if m not in self.measured:
            return "--"
        if label == "model":  # a claim about the thesis's code, not the model: bodypoint's AB4 is another code
            return f"n/a (\\texttt{{{m}}} keeps its history: {self.measured[m]:.2f} measured)"
        return f"{'yes' if round(self.measured[m]) == 4 else 'no'} ({self.measured[m]:.2f} measured, \\texttt{{{m}}})"


def ns_of(ns, m):
    return f"{ns[m]:.0f}"


def cost_rank(ns):
    return sorted(THESIS_SEVEN, key=ns.get)


def ns_named(ns, m):
    return f"{m.replace('thesis-', '')} {ns_of(ns, m)}"


def thesis_claims(t):
    """Every claim of thesis chapter 4 and of its conclusions: (claim, where in the thesis, its test)."""
    E, K, sweep, cost, rank, named = "max_rel_dE", "max_rel_dK2sq", t.sweep, t.cost, cost_rank, ns_named
    return [
        ("Symplectic schemes lose less energy than RK4 and AB4 at every $d$", "4.1, fig.~4.1",
         sweep("d", E, below(SYMPLECTIC, STANDARD))),
        ("Yoshida~6 loses the least energy of the symplectic schemes at every $d$", "4.1, fig.~4.2",
         sweep("d", E, smallest("thesis-y6", SYMPLECTIC))),
        (f"Near the centre ($L \\le {NEAR_L}$) symplectic schemes lose more energy than RK4 and AB4", "4.2, fig.~4.3",
         sweep("L", E, below(STANDARD, SYMPLECTIC), lambda v: v <= NEAR_L)),
        (f"Farther out ($L > {NEAR_L}$) they lose less", "4.2, fig.~4.3",
         sweep("L", E, below(SYMPLECTIC, STANDARD), lambda v: v > NEAR_L)),
        ("Yoshida~6 is the most accurate symplectic scheme over $L$", "4.2, fig.~4.4",
         sweep("L", E, smallest("thesis-y6", SYMPLECTIC))),
        ("Symplectic Euler, first order, is accurate: below RK4 and AB4 over $L$", "4.2, fig.~4.4",
         sweep("L", E, below(["thesis-euler"], STANDARD))),
        (f"At coarse steps ($h \\ge {sci(COARSE_H)}$) symplectic schemes lose far more energy than RK4 and AB4", "4.3, fig.~4.5",
         sweep("h", E, below(STANDARD, SYMPLECTIC), lambda v: v >= COARSE_H)),
        (f"At small steps ($h \\le {sci(SMALL_H)}$) they lose less", "4.3, fig.~4.6",
         sweep("h", E, below(SYMPLECTIC, STANDARD), lambda v: v <= SMALL_H)),
        (f"Yoshida~6 is best at small steps ($h \\le {sci(SMALL_H)}$)", "4.3, fig.~4.7",
         sweep("h", E, smallest("thesis-y6", SYMPLECTIC), lambda v: v <= SMALL_H)),
        ("RK4 and AB4 conserve $|\\Ktwo|^2$ better than the symplectic schemes (over $h$)", "4.4, fig.~4.8",
         sweep("h", K, below(STANDARD, SYMPLECTIC))),
        ("Ruth~3 has the largest $|\\Ktwo|^2$ deviation of the symplectic schemes", "4.4, fig.~4.9",
         sweep("h", K, largest("thesis-ruth3", SYMPLECTIC))),
        ("RK4 and AB4 conserve $|\\Ktwo|^2$ better at every $K_x$", "4.5, fig.~4.10--4.11",
         sweep("Kx", K, below(STANDARD, SYMPLECTIC))),
        ("Table 4.1: AB4 evaluates the right-hand side 4 times per step", "4.6, table~4.1", t.table41),
        ("Yoshida~6 is the costliest method (ns per step)", "4.6, fig.~4.12",
         cost(lambda ns: rank(ns)[-1] == "thesis-y6", lambda ns: f"{named(ns, rank(ns)[-1])}, then {named(ns, rank(ns)[-2])} ns")),
        ("Forest--Ruth~4 is faster than RK4 and AB4", "4.6, fig.~4.12",
         cost(lambda ns: ns["thesis-fr4"] < min(ns["rk4"], ns["ab4"]),
              lambda ns: f"{ns_of(ns, 'thesis-fr4')} against {ns_of(ns, 'rk4')}, {ns_of(ns, 'ab4')} ns")),
        ("Symplectic Euler's time grows slowest", "4.6, fig.~4.13",
         cost(lambda ns: rank(ns)[0] == "thesis-euler", lambda ns: f"euler {ns_of(ns, 'thesis-euler')}; least {named(ns, rank(ns)[0])} ns")),
        ("Near the centre every method loses more energy (smallest $d$ against largest)", "conclusions",
         t.near_far),
        ("Symplectic Euler is faster than RK4 and AB4 and keeps the energy better (over $d$)", "conclusions",
         t.euler_cheap_and_better),
        (f"$|\\Ktwo|^2$ is well conserved by every method (below ${sci(WELL_CONSERVED)}$ at $h = {sci(SMALL_H)}$)", "conclusions",
         t.well_conserved),
        ("Yoshida~6 gives the smallest energy deviations of the symplectic schemes ($d$, $L$, small $h$)", "conclusions",
         t.y6_overall),
    ]


def claims_table(res, out, M):
    """Every claim of thesis chapter 4 and of its conclusions, tested on the sweeps as published (the
    code's harnesses, force law, slip and loop) and on the corrected model (table 3.1)."""
    t = ClaimTests(res, M)
    claims = thesis_claims(t)
    held = {"code": 0, "model": 0}
    verdicts = {}
    with open(os.path.join(out, "tab_claims.tex"), "w") as f:
        for i, (claim, where, test) in enumerate(claims, 1):
            code, model = test("code"), test("model")
            verdicts[i] = {"code": code, "model": model}
            held["code"] += code.startswith("yes")
            held["model"] += model.startswith("yes")
            f.write(f"{i} & {claim} & {where} & {code} & {model} \\\\\n")
    conclusions(verdicts, M)
    M.add("NumClaims", count(len(claims)))
    M.add("TieDigits", count(TIE_DIGITS))
    # How many digits the five drift/kick schemes' energy deviations share over d (median over the points).
    for label, name in [("code", "TieAgreeCode"), ("model", "TieAgreeModel")]:
        digits = []
        for d in t.data[label, "d", "max_rel_dE"].values():
            vals = [d[m] for m in SYMPLECTIC if m in d and math.isfinite(d[m]) and d[m] > 0]
            if len(vals) == len(SYMPLECTIC):
                spread = (max(vals) - min(vals)) / max(vals)
                digits.append(16.0 if spread == 0 else -math.log10(spread))
        M.add(name, f"{statistics.median(digits):.0f}" if digits else "n/a")
    M.add("ClaimNearL", count(NEAR_L))
    M.add("ClaimCoarseH", sci(COARSE_H))
    M.add("ClaimSmallH", sci(SMALL_H))
    M.add("RoundoffDeviation", sci(ROUNDOFF_DEVIATION))
    M.add("ClaimsHoldCode", count(held["code"]))
    M.add("ClaimsHoldModel", count(held["model"]))


# Which claims of the table each of the thesis's conclusions rests on (the numbers of tab_claims): the
# conclusions section prints the verdicts these give, so its words cannot disagree with the table.
CONCLUSION_CLAIMS = {
    "One": [1, 4, 8],        # symplectic schemes keep the energy better away from the centre
    "TwoFirst": [17],        # near the centre every method loses accuracy
    "TwoSecond": [3],        # prefer standard schemes in close passes
    "Three": [19, 10],       # |K2|^2 kept by all, worse by the symplectic schemes
    "FourFirst": [14],       # cost grows with the order
    "FourSecond": [20],      # the sixth-order scheme is the most accurate symplectic one
}


def survival(words):
    """'survives', 'does not survive', 'survives in part' or 'is not decided' from claim verdicts."""
    heads = [w.split(" ", 1)[0] for w in words]
    decided = [h for h in heads if h in ("yes", "no", "partly")]  # tied, n/a, untimed and -- decide nothing
    if not decided:
        # The reason is the claims' own: a tie of deviations, n/a (RK4 and AB4 diverge too), untimed
        # (every time flagged: a contended machine) or no data.
        why = {"tied": "tied", "n/a": "not applicable", "untimed": "untimed: every time flagged on a contended machine",
               "--": "no data"}
        reasons = list(dict.fromkeys(why.get(h, h) for h in heads))
        return f"is not decided by these runs ({', '.join(reasons)})"
    if all(h == "yes" for h in decided):
        return "survives"
    if all(h == "no" for h in decided):
        return "does not survive"
    return "survives in part"


def conclusions(verdicts, M):
    for name, claims in CONCLUSION_CLAIMS.items():
        for label, suffix in [("model", "Model"), ("code", "Code")]:
            M.add(f"Concl{name}{suffix}", survival([verdicts[i][label] for i in claims]), math_mode=False)
        M.add(f"Concl{name}Claims", ", ".join(str(i) for i in claims), math_mode=False)


def sweeps(res, M):
    for param in ["d", "L", "Kx", "h"]:
        rows, _ = read_csv(os.path.join(res, f"{param}_sweep.csv"))
        fixed = sorted({r["method"] for r in rows})
        sweep_stats(rows, param, "", M, {"Seven": THESIS_SEVEN, "All": fixed})
        pub, _ = read_csv(os.path.join(res, f"published_{param}_sweep.csv"))
        sweep_stats(pub, param, "Pub", M, {"Seven": THESIS_SEVEN})
        diverged = sum(1 for r in pub if r.get("outcome") not in ("ok", None))
        M.add(f"PubFlagged{camel(param)}", count(diverged))
    # The h sweep: each method's deviation at the smallest step, and the smallest step at which a
    # drift/kick scheme of the thesis is flagged (diverged).
    for prefix, name in [("", "h_sweep.csv"), ("Pub", "published_h_sweep.csv")]:
        rows, _ = read_csv(os.path.join(res, name))
        hmin = min(num(r["h"]) for r in rows)
        for r in rows:
            if num(r["h"]) == hmin:
                M.add(f"HAtMin{prefix}{camel(r['method'])}", sci(num(r["max_rel_dE"])))
    rows, _ = read_csv(os.path.join(res, "h_sweep.csv"))
    flagged = [num(r["h"]) for r in rows if r["method"].startswith("thesis-") and r.get("outcome") != "ok"]
    hmin = min(num(r["h"]) for r in rows)
    M.add("HFlaggedThesis", "at no step of the sweep" if not flagged else "at every step of the sweep"
          if min(flagged) <= hmin else f"from $h = {sci(min(flagged))}$ on", math_mode=False)
    # Energy error against h: fitted slopes where the deviation lies between round-off and 1e-1.
    for prefix, name in [("", "h_sweep.csv"), ("Pub", "published_h_sweep.csv")]:
        rows, _ = read_csv(os.path.join(res, name))
        for m in sorted({r["method"] for r in rows}):
            pts = [(num(r["h"]), num(r["max_rel_dE"])) for r in rows if r["method"] == m]
            pts = [p for p in pts if ORDER_WINDOW[0] < p[1] < 1e-1]
            if len(pts) >= 3:
                M.add(f"HSlope{prefix}{camel(m)}", f"{slope([p[0] for p in pts], [p[1] for p in pts]):.2f}")
