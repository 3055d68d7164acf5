"""Section 'Numerical stability': the stress scenes, the appendix's sets, the (d, L) map and the ensembles.
"""

import math
import os
import statistics

import map_rule
import timing_rule
from macros.common import camel, count, latex_text, lost_column, num, power_of_ten, read_csv, sci, tt


# The statuses of a run that ended with numbers bodypoint does not vouch for (docs/physics.md,
# "Resolution and accuracy flags").
FLAGGED = ("diverged", "unresolved", "inaccurate", "collision")


def stress(res, out, M):
    rows, _ = read_csv(os.path.join(res, "stress.csv"))
    M.add("StressRuns", count(len(rows)))
    for status, name in [("ok", "StressOk"), ("refused", "StressRefused"), ("failed", "StressFailed")]:
        M.add(name, count(sum(1 for r in rows if r["outcome"] == status)))
    M.add("StressFlagged", count(sum(1 for r in rows if r["outcome"] in FLAGGED)))
    cases, methods = [], []
    for r in rows:
        if r["case"] not in cases:
            cases.append(r["case"])
        if r["method"] not in methods:
            methods.append(r["method"])
    cell = {(r["case"], r["method"]): r for r in rows}
    with open(os.path.join(out, "tab_stress_head.tex"), "w") as f:
        f.write("case & " + " & ".join(f"\\rotatebox{{90}}{{{tt(m)}}}" for m in methods) + " \\\\\n")
    with open(os.path.join(out, "tab_stress.tex"), "w") as f:
        for c in cases:
            cells = []
            for m in methods:
                r = cell.get((c, m))
                if r is None:
                    cells.append("")
                elif r["outcome"] == "ok":
                    # One digit and the exponent (3e-7 as $3\\mathrm{e}{-7}$): twelve methods' columns fit the page.
                    v = num(r["max_rel_dE"])
                    if not (math.isfinite(v) and v > 0):
                        cells.append(sci(v))
                        continue
                    mantissa, exponent = f"{v:.0e}".split("e")
                    cells.append(f"${mantissa}\\mathrm{{e}}{{{int(exponent)}}}$")
                else:
                    cells.append({"refused": "ref.", "failed": "stop.", "diverged": "\\textbf{div.}",
                                  "unresolved": "\\textbf{unres.}", "inaccurate": "\\textbf{inacc.}",
                                  "collision": "\\textbf{col.}"}[r["outcome"]])
            label = c.replace("_", "\\_").replace("|K1|", "$|K_1|$")
            f.write(f"{label} & " + " & ".join(cells) + " \\\\\n")
        f.write("\\midrule\n")
        for title, statuses in [("ended normally", ("ok",)), ("refused with a reason", ("refused",)),
                                ("stopped with a reason", ("failed",)), ("flagged", FLAGGED)]:
            n = [sum(1 for c in cases if cell.get((c, m)) and cell[(c, m)]["outcome"] in statuses) for m in methods]
            f.write(f"\\emph{{{title}}} & " + " & ".join(str(k) for k in n) + " \\\\\n")
    M.add("StressMethodCount", str(len(methods)), math_mode=False)  # a column count, used in the preamble
    M.add("StressCases", count(len(cases)))
    for m in methods:
        M.add(f"StressFlagged{camel(m)}", count(sum(1 for r in rows if r["method"] == m and r['outcome'] in FLAGGED)))
    far_runs = [r for r in rows if r["method"] in ("lp-y4", "logh-y4", "ttl-y4") and r["outcome"] != "refused"
                and (r["case"].startswith("L=") or r["case"].startswith("|K1|"))]
    far = [num(r["max_rel_dE"]) for r in far_runs if r["outcome"] == "ok"]
    M.add("StressFarWorst", sci(max(far)) if far else "n/a")
    M.add("StressFarRun", count(len(far_runs)))
    M.add("StressFarOk", count(len(far)))
    not_ok = [f"{tt(r['method'])} at {r['case'].replace('|K1|', '$|K_1|$')} ({r['outcome']})"
              for r in far_runs if r["outcome"] != "ok"]
    M.add("StressFarNotOk", "; not: " + ", ".join(not_ok) if not_ok else "", math_mode=False)
    bound = {r["method"]: r for r in rows if r["case"].startswith("bound orbit")}
    for m, r in bound.items():
        if r["outcome"] not in ("refused", "failed"):  # a run, ok or flagged: its energy and estimated error
            M.add(f"StressBound{camel(m)}", sci(num(r["max_rel_dE"])))
            M.add(f"StressBoundErr{camel(m)}", sci(num(r["err_estimate"])))
            M.add(f"StressBoundStatus{camel(m)}", r['outcome'], math_mode=False)


def appendix(res, M):
    rows, _ = read_csv(os.path.join(res, "appendix1", "index.csv"))
    M.add("AppendixSets", count(len(rows)))
    M.add("AppendixRun", count(sum(1 for r in rows if r["file"])))
    M.add("AppendixSkipped", count(sum(1 for r in rows if not r["file"])))
    flagged = [r for r in rows if r["file"] and r["outcome"] != "ok"]
    M.add("AppendixFlagged", count(len(flagged)))
    # By status: how many, and which sets where they are few.
    parts = []
    for status in FLAGGED:
        sets = [f"P1.{r['figure']}" for r in flagged if r['outcome'] == status]
        if sets:
            parts.append(f"{len(sets)} {status}" + (f" ({', '.join(sets)})" if len(sets) <= 3 else ""))
    if flagged:
        dE = [num(r["max_rel_dE"]) for r in flagged if r["outcome"] == "inaccurate"]
        if dE:
            parts.append(f"energy deviations of the inaccurate ones from ${sci(min(dE))}$ to ${sci(max(dE))}$")
    M.add("AppendixFlaggedSets", "; ".join(parts) or "none", math_mode=False)
    for r in rows:
        if r["file"] and r["figure"] == "3":
            traj, _ = read_csv(os.path.join(res, "appendix1", r["file"]))
            last = traj[-1]
            M.add("AppendixPThreeFinalR", sci(math.hypot(num(last["Rx"]), num(last["Ry"]))))
            M.add("AppendixPThreeD", sci(num(r["m"]) * num(r["J"]) - num(r["B"]) ** 2))


def map_table(rows, methods, out, M):
    """tab_map: per method of the (d, L) map its median and largest log10 max relative energy deviation, its
    share below 1e-10 and its runs not ok; whether it has a panel in fig_dL_map (map_rule.py)."""
    panels = 0
    with open(os.path.join(out, "tab_map.tex"), "w") as f:
        for m in methods:
            rs = [r for r in rows if r["method"] == m]
            logs = map_rule.log_deviations(rs)
            good = sum(1 for r in rs if r["outcome"] == "ok" and num(r["max_rel_dE"]) < 1e-10)
            uniform = map_rule.uniform(rs)
            panels += 0 if uniform else 1
            cells = [tt(m), f"${statistics.median(logs):.1f}$" if logs else "--", f"${max(logs):.1f}$" if logs else "--",
                     f"${100.0 * good / len(rs):.0f}$", count(sum(1 for r in rs if r["outcome"] != "ok")),
                     "" if uniform else "yes"]
            f.write(" & ".join(cells) + " \\\\\n")
    M.add("MapPanels", count(panels))
    M.add("MapUniformDecades", f"{map_rule.UNIFORM_DECADES:g}")


def ensembles(res, out, M):
    """The (d, L) map (study --name dL-map, timed by build.sh) and the batch throughput (bench_batch)."""
    rows, _ = read_csv(os.path.join(res, "dL_map.csv"))
    methods = list(dict.fromkeys(r["method"] for r in rows))
    points = len(rows) // len(methods)
    M.add("MapPoints", count(points))
    M.add("MapDs", count(len({r["d"] for r in rows})))
    M.add("MapLs", count(len({r["L"] for r in rows})))
    M.add("MapMethods", count(len(methods)))
    M.add("MapRuns", count(len(rows)))
    with open(os.path.join(res, "dL_map_seconds.txt")) as f:  # wall seconds, cores, share others used
        fields = f.read().split()
    seconds, cores = float(fields[0]), int(fields[1])
    # One run (a study of minutes is not repeated: the stated exemption); judged by the share of the
    # cores other processes used while it ran.
    others = num(fields[2]) if len(fields) > 2 else float("nan")
    flag = M.rule.flag(None, others, 0.0, process=True)
    M.ledger.count("the $(d, L)$ map's wall time", [flag])
    if flag:
        M.add("MapTime", f"(its wall time flagged: {latex_text(flag)})", math_mode=False)
        M.ledger.lost("the $(d, L)$ map's wall time (section~\\ref{sec:map})", flag)
    else:
        M.add("MapTime", f"in ${sci(seconds)}$~s of wall time", math_mode=False)
    M.add("MapCores", count(cores))
    # Share of the map each family keeps below 1e-10 relative energy error (status ok).
    def share(pick, bound=1e-10):
        rs = [r for r in rows if pick(r["method"])]
        good = sum(1 for r in rs if r["outcome"] == "ok" and num(r["max_rel_dE"]) < bound)
        return 100.0 * good / len(rs)
    M.add("MapShareLp", sci(share(lambda m: m.startswith("lp-")), 3))
    M.add("MapShareThesis", sci(share(lambda m: m.startswith("thesis-")), 3))
    M.add("MapShareRk", sci(share(lambda m: m in ("rk4", "ab4")), 3))
    M.add("MapNotOk", count(sum(1 for r in rows if r["outcome"] != "ok")))
    map_table(rows, methods, out, M)
    # bench_batch: items_per_second of the scalar loop and of each width, per method; a speed-up only
    # between two times that count under the timing rule.
    bench = timing_rule.benchmark(os.path.join(res, "bench_batch.csv"), M.rule)
    rate = {name: num(r["items_per_second"]) for name, r in bench.items() if not r["flag"]}
    widths = sorted({int(k.rsplit("/w", 1)[1]) for k in bench if k.startswith("BM_SweepBatch/")})
    wide = widths[-1]
    M.add("BatchWidth", count(wide))
    M.add("MapBatchWidthText", f"{wide} lanes at a time on this machine", math_mode=False)
    ratios = {}
    for k, v in rate.items():
        if k.startswith("BM_SweepScalar/") and f"BM_SweepBatch/{k.split('/', 1)[1]}/w{wide}" in rate:
            m = k.split("/", 1)[1]
            ratios[m] = rate[f"BM_SweepBatch/{m}/w{wide}"] / v
    lp = "lp-y4"
    if ratios:
        text = f"${sci(min(ratios.values()))}$--${sci(max(ratios.values()))}$ times faster per core"
        if lp in ratios:
            text += (f" than the scalar loop (\\cmd{{bench\\_batch}}: ${sci(rate[f'BM_SweepBatch/{lp}/w{wide}'])}$ against "
                     f"${sci(rate[f'BM_SweepScalar/{lp}'])}$ trajectory-steps per second for \\cmd{{{lp}}})")
        else:
            text += " than the scalar loop (\\cmd{bench\\_batch})"
    else:
        text = "faster per core than the scalar loop, by how much untimed in this copy (every \\cmd{bench\\_batch} pair flagged)"
        lost_column(M, "the batch speed-ups (section~\\ref{sec:map})", [r["flag"] for r in bench.values()])
    M.add("BatchSpeedupText", text, math_mode=False)
    scaling_text(res, M)


def scaling_text(res, M):
    """scripts/ensemble-scaling.sh: one sweep every way it runs, each mode's median of interleaved
    repeats judged by the timing rule (spread, the share of the cores others used); a speed-up or an
    efficiency only between times that count."""
    scaling = {r["mode"]: r for r in read_csv(os.path.join(res, "scaling.csv"))[0]}
    flags = {m: M.rule.flag(int(num(r.get("repeats")) if r.get("repeats") else 1), num(r.get("others_share")),
                            num(r.get("spread")), process=True) for m, r in scaling.items()}
    M.ledger.count("parallel runs", flags.values())
    ok = lambda *modes: all(m in scaling and not flags[m] for m in modes)  # noqa: E731
    if ok("scalar1", "simd1"):
        lanes = (f"lanes run ${sci(num(scaling['simd1']['speedup_vs_scalar']))}$ times the scalar loop's "
                 f"${sci(num(scaling['scalar1']['traj_steps_per_s']))}$ trajectory-steps per second on one core")
    else:
        lanes = "the speed-up of lanes on one core is untimed in this copy (its times flagged)"
    parts = []
    for mode, words in [("simd2", "with two threads"), ("mpi2", "with two MPI ranks"),
                        ("shards2", "with two shards and a merge")]:
        if mode not in scaling:
            parts.append(f"not measured {words} (no \\cmd{{mpirun}})")
        elif ok(mode, "simd1"):
            parts.append(f"${sci(100 * num(scaling[mode]['parallel_efficiency']), 2)}\\%$ {words}")
        else:
            parts.append(f"untimed {words} (flagged: {latex_text(flags[mode] or flags['simd1'])})")
    efficiency = f"on two cores the parallel efficiency is {', '.join(parts[:-1])} and {parts[-1]}"
    if ok("mpi2-startup"):
        startup = (f"; starting and ending two MPI ranks alone takes ${sci(num(scaling['mpi2-startup']['wall_s']))}$~s, "
                   "which a sweep of this size does not amortise")
    else:
        startup = ""
    M.add("ScalingText", f"{lanes}; {efficiency} (start-up of the processes included{startup})", math_mode=False)
    if not any(ok(m, "simd1") for m in ("simd2", "mpi2", "shards2")):
        lost_column(M, "the parallel efficiencies (section~\\ref{sec:map})", list(flags.values()))


def map_scale_text(res, M):
    """bench/map_at_scale.py: a map of the thesis's scene over (d, B), auto at one TOL on two threads. Its
    force evaluations and delivered accuracy are printed always; its CPU and wall time per trajectory where
    the timing rule lets them count (repeats, spread, the share of the cores others used)."""
    path = os.path.join(res, "map_scale.csv")
    rows = read_csv(path)[0] if os.path.exists(path) else []
    if not rows:
        M.add("MapScaleText", "was not run in this copy", math_mode=False)
        M.add("MapScaleGrid", "a grid", math_mode=False)
        return
    r = rows[0]
    flag = M.rule.flag(int(num(r["repeats"])), num(r["others_share"]), max(num(r["cpu_spread"]), num(r["wall_spread"])),
                       process=True)
    M.ledger.count("the map at an accuracy", [flag])
    n, threads = int(num(r["rows"])), int(num(r["threads"]))
    if flag:
        time_text = f"its times untimed in this copy (flagged: {latex_text(flag)})"
        M.ledger.lost("the map at an accuracy's time per trajectory (section~\\ref{sec:map})", flag)
    else:
        time_text = (f"${sci(num(r['cpu_us_per_trajectory']), 3)}~\\mu$s of CPU time per trajectory "
                     f"(${sci(num(r['wall_us_per_trajectory']), 3)}~\\mu$s of wall time on {threads} threads; "
                     f"median of {int(num(r['repeats']))} warm runs, spread ${sci(100 * num(r['cpu_spread']), 2)}\\%$)")
    refused = n - int(num(r["ok"]))
    M.add("MapScaleText",
          f"{count(n)} trajectories at TOL {power_of_ten(num(r['tol']))} cost {time_text} and "
          f"${sci(num(r['evals_per_trajectory']), 3)}$ force evaluations per trajectory, the search included "
          f"(${sci(num(r['delivered_evals_per_trajectory']), 3)}$ in the delivered runs); the estimates' median is "
          f"${sci(num(r['estimate_median']))}$ and the largest ${sci(num(r['estimate_max']))}$ "
          f"({count(int(num(r['above_tol'])))} above TOL, {count(refused)} {'row' if refused == 1 else 'rows'} refused), and "
          f"{count(int(num(r['sample'])))} rows checked against long-double references erred at most "
          f"${sci(num(r['error_max']))}$ (median ${sci(num(r['error_median']))}$)", math_mode=False)
    M.add("MapScaleGrid", f"$d$ from ${sci(num(r['d_from']))}$ to ${sci(num(r['d_to']))}$ and $B$ from "
          f"${sci(num(r['B_from']))}$ to ${sci(num(r['B_to']))}$, {count(int(num(r['points'])))} values each, "
          f"$t = {sci(num(r['t_end']))}$", math_mode=False)
