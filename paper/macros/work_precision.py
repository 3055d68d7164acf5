"""Section 'Work against precision': auto against the peers by TOL, the estimate's prices and grid, its branches,
the far field and far-ip.
"""

import csv
import math
import os
import re
import statistics

from catalogue import family, table
from macros.close import THIRD_PARTY
from macros.common import (
    below, camel, count, latex_cell, latex_text, md_table, num, power_of_ten, read_csv, reference_errors, sci,
    tt,
)


def trust_prices(rows, body, M):
    """The two prices of trust (issue #55) from the by-tol summary's rows `body` and by_tol.csv's `rows`."""
    # The price of trust (issue #55): auto's whole call against bodypoint's own fastest configuration
    # delivering TOL, in force evaluations (column 19; its time, column 20, where both times count), and what
    # its search costs beyond the run it delivers (column 21).
    own = [num(row[19].rstrip("x")) for row in body if len(row) > 21 and row[19].endswith("x")]
    own_time = [num(row[20].rstrip("x")) for row in body if len(row) > 21 and row[20].endswith("x")]
    search = [num(row[21].rstrip("x")) for row in body if len(row) > 21 and row[21].endswith("x")]
    M.add("AutoOverOwnEvals", f"a median ${sci(statistics.median(own))}$ times (${sci(min(own))}$ to ${sci(max(own))}$)"
          if own else "not measured", math_mode=False)
    M.add("AutoOverOwnTime", f"${sci(min(own_time))}$ to ${sci(max(own_time))}$ times in time" if own_time else
          "untimed (every comparison's time flagged)", math_mode=False)
    if not own_time:
        M.ledger.lost("table~\\ref{tab:bytol}: auto against bodypoint's fastest configuration, in time",
                      "every comparison's time flagged")
    M.add("AutoSearchOverRun", f"${sci(min(search))}$ to ${sci(max(search))}$ times" if search else
          "an unmeasured multiple of (no search of \\cmd{auto} in this copy's by-tol table)", math_mode=False)
    # The second price on the same configurations: their default error estimate (simulate --h), in force
    # evaluations beyond the run (by_tol.csv's own rows; ks, whose estimate evaluates no force, left out).
    prices = [num(r["estimate_force_evals"]) / num(r["force_evals"]) for r in rows
              if r["kind"] == "own" and r.get("estimate_force_evals") and num(r["estimate_force_evals"]) > 0
              and num(r["force_evals"]) > 0]
    # The price a user pays who picks a configuration by hand and must trust it without knowing the error: the
    # cheapest own configuration that delivers TOL and whose default estimate says so, its run and estimate
    # (by_tol.csv's auto rows, trusted_force_evals), and auto's whole call over it (ks, exact, left out).
    trusted = [num(r["force_evals"]) / num(r["trusted_force_evals"]) for r in rows
               if r["kind"] == "auto" and r.get("trusted_force_evals") and num(r["trusted_force_evals"]) > 0
               and num(r["force_evals"]) > 0 and r["met"] == "yes"]
    M.add("AutoOverTrusted", f"a median ${sci(statistics.median(trusted))}$ times (${sci(min(trusted))}$ to "
          f"${sci(max(trusted))}$, {count(len(trusted))} cases)" if trusted else "not measured", math_mode=False)
    M.add("OwnEstimatePrice", f"a median ${sci(statistics.median(prices))}$ times their run's force evaluations "
          f"(${sci(min(prices))}$ to ${sci(max(prices))}$, {count(len(prices))} configurations)" if prices else
          "not measured (no own configuration of this copy's by-tol table has an estimate)", math_mode=False)


def refusal_clause(rows, auto, M):
    """The text's clause on auto's refusals in the by-tol table."""
    # A refusal is not a miss: auto says why it will not try (runs that differ only in rounding differ by
    # more than TOL on the scene, or the search's budget). The clause names where, and whether any peer
    # configuration delivered that TOL there (then the refusal turned away a reachable answer).
    refused = [r for r in auto if r["met"] == "refused"]
    where = {}
    for r in refused:
        where.setdefault(r["scene"], []).append(power_of_ten(num(r["tol"])))
    # Each peer run once, however many of the scene's refused TOLs it delivered.
    reached = [p for p in rows if p["kind"] in ("at-tol", "ladder") and any(
        p["scene"] == r["scene"] and num(p["err"]) <= num(r["tol"]) for r in refused)]
    peers_did = (f"although {count(len(reached))} peer runs delivered it" if reached else "no peer run delivered it either")
    M.add("AutoRefusedClause", f" and refused the other {count(len(refused))}, saying why "
          f"({'; '.join(f'{tt(k)} at ' + ', '.join(v) for k, v in where.items())}; {peers_did})" if refused else "",
          math_mode=False)


def auto_table_rule(auto):
    """The composition table (the catalogue's, as table tab:compositions names it) auto took at each TOL of
    the by-TOL table, read from its runs (ks, which has none, and refusals left out), as a clause:
    "verlet at 10^-4, y4 at 10^-5, pefrl from 10^-6 to 10^-8, ...". A TOL at which the scenes took
    different tables names each."""
    by_tol = {}
    for r in auto:
        if table(r["method"]) and r["met"] == "yes":
            by_tol.setdefault(num(r["tol"]), set()).add(table(r["method"]))
    groups = []  # [table, first TOL, last TOL], TOL falling
    for tol in sorted(by_tol, reverse=True):
        tables = sorted(by_tol[tol])
        name = " or ".join(tt(t) for t in tables) + ("" if len(tables) == 1 else " by scene")
        if groups and groups[-1][0] == name:
            groups[-1][2] = tol
        else:
            groups.append([name, tol, tol])
    if not groups:
        return "no table (no run of table~\\ref{tab:bytol} met its TOL)"
    return ", ".join(f"{n} at {power_of_ten(a)}" if a == b else f"{n} from {power_of_ten(a)} to {power_of_ten(b)}"
                     for n, a, b in groups)


def spinning_peer_runs(spinning, M):
    """What the peers asked for TOL on the spinning scenes delivered: PeerSpinDelivered, a clause of the
    text. Table tab:bytol's peers are the third-party ones; the clause says which of the runs that
    delivered were our own logh-bs."""
    met = [r for r in spinning if r["met"] == "yes"]
    third = [r for r in spinning if family(r["method"]) in THIRD_PARTY]
    delivered = f"{count(len(met))} of {count(len(spinning))} such peer runs delivered it"
    if len(third) < len(spinning):
        delivered += (f" ({count(sum(1 for r in met if r not in third))} of them runs of \\cmd{{logh-bs}}, our own "
                      f"extrapolation code, which table~\\ref{{tab:bytol}} leaves out; "
                      f"{count(sum(1 for r in third if r['met'] == 'yes'))} of the third-party peers' {count(len(third))})")
    M.add("PeerSpinDelivered", delivered, math_mode=False)


def by_tol(res, out, M):
    rows, _ = read_csv(os.path.join(res, "by_tol.csv"))
    auto = [r for r in rows if r["kind"] == "auto"]
    met = [r for r in auto if r["met"] == "yes"]
    M.add("AutoRuns", count(len(auto)))
    M.add("AutoMet", count(len(met)))
    refusal_clause(rows, auto, M)
    ratios = [num(r["err_estimate"]) / num(r["err"]) for r in met if num(r["err"]) > 0]
    M.add("AutoEstLow", sci(min(ratios)) if ratios else "n/a")
    M.add("AutoEstHigh", sci(max(ratios)) if ratios else "n/a")
    M.add("AutoTableRule", auto_table_rule(auto), math_mode=False)
    peers = [r for r in rows if r["kind"] == "at-tol"]
    M.add("PeerRuns", count(len(peers)))
    M.add("PeerMet", count(sum(1 for r in peers if r["met"] == "yes")))
    M.add("NumByTolScenes", count(len({r["scene"] for r in auto})))
    head, body = md_table(os.path.join(res, "by_tol_summary.md"))
    # scene, TOL, auto, delivered, time; the fastest peer at tolerance TOL that met it, time, ratio; the
    # peer's best case, time, ratio; ratio of the delivered run alone
    keep = [0, 1, 2, 5, 7, 8, 9, 10, 12, 13, 14, 16]
    ratios, alone = {}, {}
    for row in body:  # auto against the peer's best case, per scene (a "-": no peer delivers TOL)
        if row[14].endswith("x"):
            ratios.setdefault(row[0], []).append(num(row[14].rstrip("x")))
        if row[16].endswith("x"):
            alone.setdefault(row[0], []).append(num(row[16].rstrip("x")))
    spinning_peer_runs([r for r in peers if r["scene"] != "material"], M)
    # Against the fastest peer asked for TOL that delivered it, on the spinning scenes: a clause of the
    # text, empty where no such peer run exists.
    at_tol = [num(row[10].rstrip("x")) for row in body if row[0] != "material" and row[10].endswith("x")]
    clause = ""
    if at_tol:
        clause = (f"; against the fastest of those that did, \\cmd{{auto}} is ${sci(min(at_tol))}$ to "
                  f"${sci(max(at_tol))}$ times as fast")
    M.add("AutoVsPeerAtTolSpin", clause, math_mode=False)
    # A ratio whose times do not count (flagged) is left out; none left: the range says so in words
    # (a contended machine), not "n/a to n/a times as fast".
    def ratio_range(name, values, what):
        M.add(f"{name}Range", f"${sci(min(values))}$ to ${sci(max(values))}$ times as fast" if values else
              "untimed (every comparison's time flagged)", math_mode=False)
        if not values:
            M.ledger.lost(what, "every comparison's time flagged")
    ratio_range("AutoAloneSpin", [r for scene, rs in alone.items() if scene != "material" for r in rs],
                "table~\\ref{tab:bytol}: auto's delivered run against the peers' best case (spinning scenes)")
    ratio_range("AutoVsPeerSpin", [r for scene, rs in ratios.items() if scene != "material" for r in rs],
                "table~\\ref{tab:bytol}: auto against the peers' best case (spinning scenes)")
    ratio_range("AutoVsPeerMaterial", ratios.get("material", []),
                "table~\\ref{tab:bytol}: auto against the peers' best case (material point)")
    trust_prices(rows, body, M)
    floor = reference_errors(res)  # the same long-double references as work-precision's
    with open(os.path.join(out, "tab_by_tol.tex"), "w") as f:
        for row in body:
            cells = [latex_cell(row[i]) for i in keep]
            # A delivered error below the reference's own error is not resolved: it reads "< that error".
            if row[2] == "refused":  # nothing delivered: no error to print
                cells[keep.index(5)] = "-"
            elif num(row[5]) < floor.get(row[0], 0.0):
                cells[keep.index(5)] = f"$<${floor[row[0]]:.0e}"  # as the other errors of the table print
            f.write(" & ".join(cells) + " \\\\\n")


def estimate_cost(res, M):
    """The price of a run's error estimate (bench/estimate_cost.py): the default simulate's and Python's
    integrate's CPU time with it over without it, each side's median under the paper's timing rule."""
    path = os.path.join(res, "estimate_cost.csv")
    rows = read_csv(path)[0] if os.path.exists(path) else []
    cases = {"default simulate": "the README's run", "python integrate lp-y4 h=1e-4 t=50": "Python's integrate of it"}
    parts, flags = [], []
    for r in rows:
        if r["case"] not in cases:
            continue
        repeats = int(r["repeats"])
        why = "; ".join(w for w in (M.rule.flag(repeats, num(r["wait_with"]), num(r["spread_with"])),
                                    M.rule.flag(repeats, num(r["wait_without"]), num(r["spread_without"]))) if w)
        flags.append(why)
        parts.append(f"{cases[r['case']]} " + (f"untimed ({latex_text(why)})" if why else f"${num(r['ratio']):.2f}$ times"))
    M.ledger.count("estimate price", flags)
    if flags and all(flags):
        M.ledger.lost("the price of a run's error estimate (what trust costs)", f"{len(flags)} of {len(flags)} times flagged")
    M.add("EstimatePrice", ("its CPU time with the estimate over without it: " + ", ".join(parts) +
                            " (\\cmd{bench/estimate\\_cost.py}, medians of " + rows[0]["repeats"] + " interleaved repeats)")
          if parts else "not measured in this copy", math_mode=False)


def estimate_grid(res, M):
    """The accuracy mode on bench/estimate_grid.py's 768 runs: misses, the error against its estimate
    (its distribution) and how far below TOL the delivered error lies."""
    path = os.path.join(res, "estimate_grid.csv")
    with open(path) as f:
        rows = list(csv.DictReader(f))
    ran = [r for r in rows if r["outcome"] == "ok"]
    M.add("GridRuns", count(len(rows)))
    M.add("GridScenes", count(len({(r["d"], r["Kz"], r["B"], r["Kx"]) for r in rows})))
    for key in ["d", "Kz", "B"]:
        values = sorted({num(r[key]) for r in rows})
        M.add(f"Grid{camel(key)}Min", f"{values[0]:g}")
        M.add(f"Grid{camel(key)}Max", f"{values[-1]:g}")
    M.add("GridKxCount", count(len({r["Kx"] for r in rows})))
    tols = sorted({num(r["tol"]) for r in rows}, reverse=True)
    M.add("GridTols", ", ".join(power_of_ten(t) for t in tols), math_mode=False)
    M.add("GridRefused", count(len(rows) - len(ran)))
    M.add("GridMissed", count(sum(1 for r in ran if num(r["err"]) > num(r["tol"]))))
    # Below 1e-13 the reference's error and the run's round-off are of the error's size (estimate_grid.py).
    comparable = [r for r in ran if num(r["err"]) > 1e-13 and num(r["err_estimate"]) > 0]
    ratio = sorted(num(r["err"]) / num(r["err_estimate"]) for r in comparable)
    M.add("GridCompared", count(len(ratio)))
    M.add("GridRatioMedian", f"{statistics.median(ratio):.2f}")
    M.add("GridRatioWorst", f"{max(ratio):.2f}")
    M.add("GridRatioLow", f"{min(ratio):.2g}")
    M.add("GridWithinThree", count(sum(1 for x in ratio if 1 / 3 <= x <= 3)))
    below = sorted(num(r["tol"]) / num(r["err"]) for r in ran if num(r["err"]) > 0)
    M.add("GridUnderMedian", f"{statistics.median(below):.2g}")
    M.add("GridUnderMax", sci(max(below)))


def estimate_branches(res, out, M):
    """The accuracy mode on its other branches (bench/estimate_grid.py --branches): a row per branch of
    tab_branches (runs, methods, refused, missed, estimates more than 3x below or above the error, the
    worst error/estimate), and the counts the text quotes."""
    with open(os.path.join(res, "estimate_branches.csv")) as f:
        rows = list(csv.DictReader(f))
    body, totals = [], {"runs": 0, "missed": 0, "under": 0}
    for branch in dict.fromkeys(r["branch"] for r in rows):
        group = [r for r in rows if r["branch"] == branch]
        ran = [r for r in group if r["outcome"] == "ok" and r["err"]]
        unchecked = sum(1 for r in group if r["outcome"] == "ok" and not r["err"])
        # Below 1e-13 the reference's error and the run's round-off are of the error's size (estimate_grid.py).
        comparable = [r for r in ran if num(r["err"]) > 1e-13 and num(r["err_estimate"]) > 0]
        ratios = [num(r["err"]) / num(r["err_estimate"]) for r in comparable]
        missed = sum(1 for r in ran if num(r["err"]) > num(r["tol"]))
        under = sum(1 for x in ratios if x > 3)
        over = sum(1 for x in ratios if x < 1 / 3)
        methods = ", ".join(sorted({r["method"] for r in ran}))
        worst = f"{max(ratios):.2f}" if ratios else "--"
        refused = len(group) - len(ran) - unchecked
        body.append([branch, count(len(group)), f"\\texttt{{{methods}}}", count(refused), count(unchecked),
                     count(missed), count(under), count(over), worst])
        totals["runs"] += len(group)
        totals["missed"] += missed
        totals["under"] += under
    with open(os.path.join(out, "tab_branches.tex"), "w") as f:
        for row in body:
            f.write(" & ".join(row) + " \\\\\n")
    M.add("BranchRuns", count(totals["runs"]))
    M.add("BranchMissed", count(totals["missed"]))
    M.add("BranchUnder", count(totals["under"]))
    tols = sorted({num(r["tol"]) for r in rows}, reverse=True)
    M.add("BranchTols", ", ".join(power_of_ten(t) for t in tols), math_mode=False)
    branch_outliers(rows, M)
    far_ip_against_auto(rows, M)


def far_ip_against_auto(rows, M):
    """far-ip's whole call under --tol against auto's on the same far passes (the branches' "far-ip" and "lp
    far field" rows), in force evaluations (search and delivered run): per TOL the median and range of the
    ratio (a far-ip evaluation is the force with its Jacobian; the times are bench/several_centres.py's)."""
    def whole(r):
        return num(r["force_evals"]) + num(r["search_force_evals"])
    auto = {(r["scene"], r["tol"]): r for r in rows if r["branch"] == "lp far field" and r["outcome"] == "ok"}
    parts = []
    for tol in sorted({r["tol"] for r in rows}, key=float, reverse=True):
        ratios = [whole(r) / whole(auto[r["scene"], tol]) for r in rows
                  if r["branch"] == "far-ip" and r["outcome"] == "ok" and r["tol"] == tol and (r["scene"], tol) in auto]
        if ratios:
            parts.append(f"${sci(statistics.median(ratios))}$ (${sci(min(ratios))}$ to ${sci(max(ratios))}$) at "
                         f"{power_of_ten(float(tol))}")
    M.add("FarIpVsAutoEvals", ", ".join(parts) if parts else "not measured in this copy", math_mode=False)


def branch_outliers(rows, M):
    """Where the branches' estimates are more than 3 times off (issue #83 M4), beside the rounding level the
    accuracy mode measured on the same scene (a refusal's "differ by X": runs that differ only in rounding),
    which bounds what such an error can be and below which every TOL is refused."""
    level = {}
    for r in rows:
        m = re.search(r"differ by ([0-9.e+-]+)", r.get("reason", ""))
        if m:
            level[r["scene"]] = max(level.get(r["scene"], 0.0), float(m.group(1)))
    parts, low = [], 0
    for r in rows:
        if r["outcome"] != "ok" or not r["err"] or num(r["err"]) <= 1e-13 or num(r["err_estimate"]) <= 0:
            continue
        if num(r["err"]) / num(r["err_estimate"]) > 3:
            low += 1
            where = (f"where runs that differ only in rounding differ by ${sci(level[r['scene']])}$"
                     if r["scene"] in level else "where the scene's rounding level was not measured")
            parts.append(f"{tt(r['method'])} at TOL {power_of_ten(num(r['tol']))} ({r['scene']}) erred "
                         f"${sci(num(r['err']))}$ with an estimate of ${sci(num(r['err_estimate']))}$, {where}")
    high = [r for r in rows if r["outcome"] == "ok" and r["err"] and num(r["err"]) > 1e-13
            and num(r["err_estimate"]) > 3 * num(r["err"])]
    if high:
        parts.append(f"the {count(len(high))} estimates more than 3 times high are at errors of at most "
                     f"${sci(max(num(r['err']) for r in high))}$ and estimates of at most "
                     f"${sci(max(num(r['err_estimate']) for r in high))}$"
                     + (f", against rounding levels of ${sci(min(level.values()))}$ to ${sci(max(level.values()))}$ "
                        "measured on these scenes" if level else ""))
    M.add("BranchOutliersText", "; ".join(parts) if parts else "no estimate is more than 3 times off", math_mode=False)
    below = "below the rounding level the same scene shows, where Richardson does not hold"
    if low == 1:
        text = f"; the low one is a step search's Richardson estimate {below}"
    elif low:
        text = f"; the low ones are step searches' Richardson estimates {below}"
    else:
        text = ("; none is low: a step search whose estimates stop falling where its runs differ by less than "
                "$10^{-8}$ measures its answer's rounding (runs that differ only in rounding) and adds it to its "
                "estimate before delivering it, at any TOL, as it does below $10^{-10}$")
    M.add("BranchLowText", text, math_mode=False)


# The far pass's error is smooth in the step below this spin angle per step (radians): the largest
# step of the table below it is the one quoted as the last smooth one (bench/far_field.py: 2.75 rad,
# the next step, 3.09 rad, already meets the resonance at pi).
FAR_SMOOTH_BELOW = 2.8


def far_field(res, out, M):
    """Where the steps go on the close scene (bench/far_field.py): auto's delivered run and the peers at
    tolerance TOL; and the far pass's error against the spin angle per step (its resonances)."""
    rows, _ = read_csv(os.path.join(res, "far_field_share.csv"))
    auto = [r for r in rows if r["who"] == "auto"]
    peers = [r for r in rows if r["who"] != "auto"]
    for name, group in [("FarAuto", auto), ("FarPeer", peers)]:
        for radius in ("5", "50"):
            shares = [100 * num(r[f"share_beyond_{radius}"]) for r in group]
            word = "Five" if radius == "5" else "Fifty"
            M.add(f"{name}Share{word}Low", f"{min(shares):.0f}")
            M.add(f"{name}Share{word}High", f"{max(shares):.0f}")

    def per_radian(r):  # force evaluations per radian of spin beyond r = 50
        return num(r["force_evals"]) / num(r["steps"]) / num(r["spin_angle_beyond_50"])

    ratios = [min(per_radian(p) for p in peers if p["tol"] == a["tol"]) / per_radian(a) for a in auto]
    with open(os.path.join(out, "tab_far_field.tex"), "w") as f:
        for r in rows:
            cells = [sci(num(r["tol"]), 1), tt(r["method"]), count(int(r["steps"])), count(int(r["force_evals"])),
                     f"{100 * num(r['share_beyond_5']):.0f}", f"{100 * num(r['share_beyond_50']):.0f}",
                     sci(num(r["spin_angle_beyond_50"])), sci(per_radian(r))]
            f.write(" & ".join(f"${c}$" if "times" in c else c for c in cells) + " \\\\\n")
    M.add("FarPerRadianLow", sci(min(ratios)))
    M.add("FarPerRadianHigh", sci(max(ratios)))
    res_rows, _ = read_csv(os.path.join(res, "far_field_resonances.csv"))
    kl6 = {round(num(r["spin_angle"]), 2): num(r["err"]) for r in res_rows if r["method"] == "lp-kl6"}

    def nearest(angle):
        return kl6[min(kl6, key=lambda a: abs(a - angle))]

    smooth = max(a for a in kl6 if a < FAR_SMOOTH_BELOW)
    M.add("FarSmoothAngle", sci(smooth))
    M.add("FarSmoothErr", sci(kl6[smooth]))
    M.add("FarPiErr", sci(nearest(math.pi)))
    M.add("FarTwoPiErr", sci(nearest(2 * math.pi)))
    far_ip(res_rows, M)


# far-ip's errors are quoted at the steps nearest these spin angles per step (radians), and the peer
# beside it at its cheapest tolerance that errs no more than far-ip at the first of them.
FAR_IP_ANGLES = [("Twenty", 20.0), ("Forty", 40.0)]


# Errors within this factor of each other count as one accuracy where both sit at the reference's floor.
FAR_SPLIT_SLACK = 1.5


def far_ip(rows, M):
    """The far-field collocation on the same pass (bench/far_field.py): error and force evaluations per
    radian of spin at tens of radians per step, beside GSL's rk8pd at a tolerance per step."""
    far = [r for r in rows if r["method"] == "far-ip"]
    for word, angle in FAR_IP_ANGLES:
        r = min(far, key=lambda x: abs(num(x["spin_angle"]) - angle))
        M.add(f"FarIpAngle{word}", f"{num(r['spin_angle']):.3g}")
        M.add(f"FarIpErr{word}", sci(num(r["err"])))
        M.add(f"FarIpPerRad{word}", f"{num(r['evals_per_radian']):.2g}")
    first = min(far, key=lambda x: abs(num(x["spin_angle"]) - FAR_IP_ANGLES[0][1]))
    # The splitting beside it: lp-kl6's cheapest step within FAR_SPLIT_SLACK of far-ip's error (both at the
    # reference's floor there).
    split = [r for r in rows if r["method"] == "lp-kl6" and num(r["err"]) <= FAR_SPLIT_SLACK * num(first["err"])]
    if split:
        best = min(split, key=lambda x: num(x["evals_per_radian"]))
        M.add("FarSplitBeside", f"\\cmd{{lp-kl6}} needs {num(best['evals_per_radian']):.2g} per radian for "
              f"\\ensuremath{{{sci(num(best['err']))}}} ({num(best['spin_angle']):.2g} rad per step)",
              math_mode=False)
    else:
        M.add("FarSplitBeside", "\\cmd{lp-kl6} errs more at every step of the table", math_mode=False)
    peers = [r for r in rows if r["method"] == "gsl-rk8pd" and num(r["err"]) <= num(first["err"])]
    if peers:
        peer = min(peers, key=lambda x: num(x["evals_per_radian"]))
        M.add("FarPeerErr", sci(num(peer["err"])))
        M.add("FarPeerPerRad", f"{num(peer['evals_per_radian']):.2g}")
        M.add("FarPeerAngle", f"{num(peer['spin_angle']):.2g}")
        text = (f"GSL's \\cmd{{rk8pd}}, at its cheapest tolerance per step that errs no more, "
                f"errs {M.defs['FarPeerErr']} with {M.defs['FarPeerPerRad']} force evaluations per radian "
                f"({M.defs['FarPeerAngle']} rad per step)")
    else:
        all_peer = [r for r in rows if r["method"] == "gsl-rk8pd"]
        text = ("GSL's \\cmd{rk8pd} errs more than that at every tolerance per step down to $10^{-14}$" if all_peer
                else "GSL, optional, is not in this build")
        if all_peer:
            best = min(all_peer, key=lambda x: num(x["err"]))
            text += (f" (its least, \\ensuremath{{{sci(num(best['err']))}}}, with "
                     f"{num(best['evals_per_radian']):.2g} force evaluations per radian)")
    M.add("FarPeerBeside", text, math_mode=False)
