"""The first page and 'Reproducing this document': the revision, the machine, the build's time and options, the
timing discipline and what a contended machine lost.
"""

import csv
import math
import os
import re
import statistics

import timing_rule
from macros.common import count, latex_text, lost_column, num, read_csv


def build_options(res, M):
    """The options paper/build.sh gave each step's command in this mode (build_options.txt)."""
    path = os.path.join(res, "build_options.txt")
    lines = open(path).read().splitlines() if os.path.exists(path) else []
    M.add("BuildOptions", "; ".join(f"\\cmd{{{latex_text(line.split(': ', 1)[0])}}}: \\cmd{{{latex_text(line.split(': ', 1)[1])}}}"
                                    for line in lines if ": " in line) or "not recorded", math_mode=False)


def build_time(res, M):
    """How long this build took to make its results (paper/build.sh writes build_seconds.txt)."""
    path = os.path.join(res, "build_seconds.txt")
    fields = open(path).read().split() if os.path.exists(path) else []
    seconds = float(fields[0]) if fields else float("nan")
    sittings = int(fields[1]) if len(fields) > 1 else 1
    M.add("BuildMinutes", f"{seconds / 60:.0f}" if math.isfinite(seconds) else "n/a")
    M.add("BuildSittings", "in one sitting" if sittings == 1 else
          f"the sum of its steps' wall times over {sittings} sittings (\\cmd{{paper/build.sh --resume}})",
          math_mode=False)


def platform(res, M):
    """The machine and software of this build's timings (paper/build.sh writes platform.txt)."""
    with open(os.path.join(res, "platform.txt")) as f:
        info = dict(line.rstrip("\n").split("=", 1) for line in f if "=" in line)
    M.add("PlatformVirtual", "a virtual machine" if info.get("virtual") == "yes" else "a physical machine",
          math_mode=False)
    for key, name in [("cpu", "PlatformCpu"), ("mhz", "PlatformMhz"), ("load", "PlatformLoad"),
                      ("cores", "PlatformCores"), ("compiler", "PlatformCompiler"),
                      ("flags", "PlatformFlags"), ("boost", "PlatformBoost"), ("eigen", "PlatformEigen"),
                      ("gsl", "PlatformGsl"), ("kernel", "PlatformKernel")]:
        M.add(name, latex_text(info.get(key, "").strip() or "unknown"), math_mode=False)


def timing_discipline(res, M):
    """How many times of this build count under the timing rules (experiments/cli/stopwatch.hpp), the rules'
    margins as the CSVs state them, and GSL as bodypoint drives it against a plain C program."""
    _, header = read_csv(os.path.join(res, "by_tol.csv"))
    rules = next(line for line in header if line.startswith("# flag:"))
    M.add("MaxWaitShare", re.search(r"by more than (\S+) %", rules).group(1))
    M.add("MaxSpread", re.search(r"spread above (\S+) %", rules).group(1))
    timing = next(line for line in header if line.startswith("# timing:"))
    M.add("TimingRepeats", re.search(r"then (\d+) repeats", timing).group(1))
    M.add("MinRepeatMs", re.search(r"lasting >= (\S+) ms", timing).group(1))
    path = os.path.join(res, "gsl_peer.csv")
    rows = []
    if os.path.exists(path):
        with open(path) as f:
            rows = list(csv.DictReader(f))
    # Only comparisons whose two times count (gsl_peer flags a row when either does not).
    ratios = [num(r["ratio_per_eval"]) for r in rows if not r["flag"]]
    if ratios:
        text = (f"cost ${min(ratios):.2f}$ to ${max(ratios):.2f}$ (median ${statistics.median(ratios):.2f}$) times, "
                f"per force evaluation, what a stand-alone C program costs")
    elif rows:
        text = "were not compared in this copy with what a stand-alone C program costs (every comparison flagged)"
        lost_column(M, "GSL against a plain C program (section~\\ref{sec:timing})", [r["flag"] for r in rows])
    else:
        text = "were not compared in this build with what a stand-alone C program costs (no GSL)"
    M.add("GslPeerCost", text, math_mode=False)
    M.add("GslPeerRuns", f"{count(len(ratios))} of {count(len(rows))} configurations whose times count", math_mode=False)


def contention(res, figs, M):
    """Every time of this build under the one timing rule: how many were taken and flagged (per study and
    in all), and, when a figure, table column or stated comparison lost every time to flags (a
    contended machine), the draft stamp on every page and the list on the first (ContendedStamp,
    ContendedNotice; both empty for a copy that lost nothing)."""
    for name, study in [("timing.csv", "timing study"), ("published_timing.csv", "timing study as published"),
                        ("work_precision.csv", "work-precision"), ("by_tol.csv", "by-tol"),
                        ("gsl_peer.csv", "GSL against plain C")]:
        if os.path.exists(os.path.join(res, name)):
            M.ledger.count(study, [r["flag"] for r in read_csv(os.path.join(res, name))[0]])
    for name, study in [("bench_steps.csv", "\\cmd{bench\\_steps}"), ("bench_batch.csv", "\\cmd{bench\\_batch}")]:
        if os.path.exists(os.path.join(res, name)):
            M.ledger.count(study, [r["flag"] for r in timing_rule.benchmark(os.path.join(res, name), M.rule).values()])
    taken, flagged = M.ledger.total()
    M.add("TimesTaken", count(taken))
    M.add("TimesFlagged", count(flagged))
    M.add("TimesFlaggedByStudy", "; ".join(f"{study} {count(M.ledger.flagged[study])} of {count(n)}"
                                           for study, n in M.ledger.taken.items()), math_mode=False)
    path = os.path.join(figs, "lost.csv") if figs else ""
    if path and os.path.exists(path):
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                M.ledger.lost(r["what"], r["why"])
    if not M.ledger.lost_items:
        M.add("ContendedStamp", "", math_mode=False)
        M.add("ContendedNotice", "", math_mode=False)
        return
    items = " ".join(f"\\item {what}: {latex_text(why)}" for what, why in M.ledger.lost_items)
    M.add("ContendedStamp", "\\contendedstamp", math_mode=False)
    M.add("ContendedNotice", "\\contendednotice{" + f"{count(flagged)} of {count(taken)}" + "}{" + items + "}",
          math_mode=False)
