"""Section 'Close encounters': the reference's error, the ladders' budget, the speedups and the close-pass table.
"""

import math
import os
import re

from catalogue import family, has_fictitious_step
from macros.common import (
    camel, count, latex_cell, lost_column, md_table, num, read_csv, reference_errors, sci, target_word, tied,
    tt,
)


def ladder_budget(res, M):
    """Whether this build's work-precision ladders cut the peers by a budget (the quick build does)."""
    _, header = read_csv(os.path.join(res, "work_precision.csv"))
    line = next((h for h in header if h.startswith("# ladders:")), "")
    m = re.search(r"end above (\S+) force evaluations; the peers' (too)?", line)
    if m and m.group(2):
        text = (f"This quick build ends every ladder, the peers' too, above ${sci(float(m.group(1)))}$ force "
                f"evaluations; the full build cuts no peer's ladder by a budget.")
    else:
        text = ("No peer's ladder is cut by an evaluation budget: a peer runs down to tolerance $10^{-14}$ or "
                "to its round-off floor (two decades that do not halve its error).")
    M.add("PeerLadderBudget", text, math_mode=False)


def reference_error(res, M):
    """The long-double reference's own error on each scene, as work-precision estimated it (the larger
    of its distances to the same integration at tolerance 1e-15 and to lp-ss10 at a small step)."""
    rel = list(reference_errors(res).values())
    M.add("RefErrMax", sci(max(rel)) if rel else "n/a")
    M.add("RefScenes", count(len(rel)))


def speedup_phrase(parts):
    """Speed-ups in words with the force evaluations beside them (which do not depend on the machine):
    "$2.0\\times$ and $2.9\\times$ as fast (the peer's force evaluations over bodypoint's: $3.1$ and
    $4.0$)"; a flagged time reads "untimed (flagged)", a target nobody reached "not compared"."""
    times = [f"${sp.rstrip('x')}\\times$" if sp.endswith("x") else "untimed (flagged)" if sp == "flagged"
             else "not compared (a side reached no target)" for sp, _, _ in parts]
    evals = [f"${sci(pe / e)}$" for _, e, pe in parts if e > 0 and pe > 0]
    return (f"{' and '.join(times)} as fast" +
            (f" (the peer's force evaluations over bodypoint's: {' and '.join(evals)})" if len(evals) == len(parts) else ""))


def tol_config(row):
    """A tolerance-driven configuration as the tables print it: tol=1e-10."""
    return f"tol={num(row['tol']):.2g}"


THIRD_PARTY = ("Boost.Odeint", "GSL", "SUNDIALS")  # peers nobody here wrote (logh-bs is our own extrapolation code)


def third_party_speedup(res, M):
    """The close encounter's cheapest bodypoint configuration against the cheapest third-party peer reaching
    1e-7 and 1e-10, by the rule of tab_close (fewest force evaluations, the next finer rung reaching it too):
    SpeedupCloseThirdPair, in time where neither time is flagged, with the evaluations' ratio beside it."""
    rows, _ = read_csv(os.path.join(res, "work_precision.csv"))
    rows = [r for r in rows if r["scene"] == "close"]
    parts, names = [], []
    for target in (1e-7, 1e-10):
        own, _ = cheapest_reaching(rows, target, lambda fam: fam not in THIRD_PARTY and fam != "logH+BS")
        peer, _ = cheapest_reaching(rows, target, lambda fam: fam in THIRD_PARTY)
        names.append("none" if peer is None else f"{tt(peer['method'])} (\\mbox{{{tol_config(peer)}}})")
        if own is None or peer is None:
            parts.append(("-", 0.0, 0.0))
            continue
        timed = not own["flag"] and not peer["flag"] and num(own["wall_s"]) > 0
        sp = f"{num(peer['wall_s']) / num(own['wall_s']):.2g}x" if timed else "flagged"
        parts.append((sp, num(own["force_evals"]), num(peer["force_evals"])))
    M.add("SpeedupCloseThirdPair", speedup_phrase(parts), math_mode=False)
    M.add("BestThirdPeerClosePair", f"{names[0]} for both" if names[0] == names[1] else " and ".join(names),
          math_mode=False)


def method_words(cell):
    """A summary's method cell in the text: "none" for "-", a tie as "a (tied with b)"."""
    if cell == "-":
        return "none"
    m = re.fullmatch(r"(\S+) \(tied: (.+)\)", cell)
    if m:
        return f"{tt(m.group(1))} (tied with {', '.join(tt(x) for x in m.group(2).split(', '))})"
    return tt(cell)


def speedup_table(res, out, M):
    head, body = md_table(os.path.join(res, "work_precision_summary.md"))
    parts = {}
    ref = reference_errors(res)
    # A target below the reference's own error decides nothing: no error under it can be measured, so
    # its row names no winner (the close and material references are about 2e-13 off).
    unresolved = [row for row in body if num(row[1]) < ref.get(row[0], 0)]
    with open(os.path.join(out, "tab_speedup.tex"), "w") as f:
        for row in body:
            if row in unresolved:
                f.write(f"{row[0]} & {row[1]} & \\multicolumn{{9}}{{l}}{{not decided: the reference is "
                        f"${sci(ref[row[0]])}$ off}} \\\\\n")
                continue
            scene, target, best, cfg, evals, t, peer, pcfg, pevals, pt, sp = row
            f.write(" & ".join(latex_cell(c) for c in row) + " \\\\\n")
            key = f"{camel(scene)}{target_word(target)}"
            M.add(f"Speedup{key}", sp.rstrip("x") if sp.endswith("x") else "n/a")
            parts[key] = (sp, num(evals), num(pevals))
            M.add(f"Best{key}", method_words(best), math_mode=False)
            M.add(f"BestPeer{key}", method_words(peer), math_mode=False)
    body = [row for row in body if row not in unresolved]
    M.add("NumSpeedupRows", count(len(body)))
    if all(not row[10].endswith("x") for row in body):
        lost_column(M, "table~\\ref{tab:speedup}, column speed-up", [row[10] for row in body if row[10] == "flagged"])
    if "CloseSeven" in parts and "CloseTen" in parts:
        M.add("SpeedupClosePair", speedup_phrase([parts["CloseSeven"], parts["CloseTen"]]), math_mode=False)
    # The pairs the text names together: one name once when both targets have the same.
    for first, second, name in [("BestCloseSeven", "BestCloseTen", "BestClosePair"),
                                ("BestPeerCloseSeven", "BestPeerCloseTen", "BestPeerClosePair"),
                                ("BestThesisSeven", "BestLongSeven", "BestThesisLongPair")]:
        a, b = M.defs.get(first, "none"), M.defs.get(second, "none")
        M.add(name, f"{a} for both" if a == b else f"{a} and {b}", math_mode=False)


def next_rung_reaches(rows, r, target):
    """Whether the next finer configuration of r's ladder (the next row of its method on its scene, as
    work_precision.csv lists a ladder coarse to fine) reaches the target too: a lucky cancellation at one
    step does not count (experiments/studies/work_precision.cpp, best_at)."""
    i = rows.index(r)
    nxt = rows[i + 1] if i + 1 < len(rows) else None
    return bool(nxt and nxt["scene"] == r["scene"] and nxt["method"] == r["method"] and num(nxt["err_rel"]) <= target)


def cheapest_reaching(rows, target, keep):
    """The cheapest configuration of the families `keep` accepts reaching `target` (err_rel), and the other
    methods tied with it. Chosen by what does not depend on the machine: the fewest force evaluations,
    counting a configuration only when the next finer rung of its ladder reaches the target too (ks: one
    configuration); equal counts: the first by name (not the faster), the others returned to be named.
    (None, []) when none reaches it."""
    ok = [r for r in rows if keep(family(r["method"])) and num(r["err_rel"]) <= target
          and (r["method"] == "ks" or next_rung_reaches(rows, r, target))]
    if not ok:
        return None, []
    best = min(ok, key=lambda r: (num(r["force_evals"]), r["method"]))
    return best, sorted({r["method"] for r in ok if r["force_evals"] == best["force_evals"]} - {best["method"]})


def close_table(res, out, M):
    """Cheapest configuration of each family reaching each target on the close encounter."""
    rows, _ = read_csv(os.path.join(res, "work_precision.csv"))
    rows = [r for r in rows if r["scene"] == "close"]
    families = ["thesis's seven", "Lie-Poisson", "time-transformed", "Boost.Odeint", "GSL", "logH+BS"]
    targets = ["1e-4", "1e-7", "1e-10"]
    with open(os.path.join(out, "tab_close.tex"), "w") as f:
        for i, target in enumerate(targets):
            power = f"$10^{{{int(math.log10(float(target)))}}}$"
            for fam in families:
                best, tied = cheapest_reaching(rows, float(target), lambda x: x == fam)
                if best is None:
                    f.write(f"{power} & {fam} & none & & & \\\\\n")
                    M.add(f"CloseEvals{camel(fam)}{target_word(target)}", "none reaching it", math_mode=False)
                    continue
                t = "\\emph{flagged}" if best["flag"] else f"{num(best['wall_s']) * 1e3:.3g}"
                m = best["method"]
                if best["tol"]:
                    cfg = tol_config(best)
                else:
                    cfg = f"{'ds' if has_fictitious_step(m) else 'h'}={num(best['h']):.3g}"
                evals = int(num(best["force_evals"]))
                names = latex_cell(f"{m} (tied: {', '.join(tied)})") if tied else tt(m)
                f.write(f"{power} & {fam} & {names} & {cfg} & {count(evals)} & {t} \\\\\n")
                M.add(f"CloseEvals{camel(fam)}{target_word(target)}", count(evals))
            if i + 1 < len(targets):
                f.write("\\midrule\n")
