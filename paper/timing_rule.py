"""One timing rule for every time the paper prints (issue #58).

The commands flag a time that does not count (experiments/cli/stopwatch.cpp): fewer repeats than the rule
asks, wall time above CPU time by more than a share (the thread waited for a core: contended), or a
spread (interquartile range over the median) above a bound. The same limits, read from the CSV header
the commands write ("# flag: ..."), judge here the times no command flags itself: Google Benchmark's
medians (bench_steps, bench_batch: real and CPU time, their coefficient of variation as the spread),
and the whole-process wall times of paper/build.sh and scripts/ensemble-scaling.sh, which carry the
share of the cores other processes used while they ran (/proc/stat) in place of their CPU time.

`Ledger` counts, per study, the times taken and flagged, and records a study, figure or table that
lost every time to flags (a contended machine): paper/make_macros.py states the counts, and a copy
with such a study is stamped "draft: contended" with the list after its abstract."""
import csv
import os
import re

# Google Benchmark writes a coefficient of variation in its time columns scaled like a time: a cv of
# 0.05 in a row of unit ns reads 5e7.
_UNIT_SCALE = {"ns": 1e9, "us": 1e6, "ms": 1e3, "s": 1.0}


class Rule:
    """The limits of experiments/cli/stopwatch.cpp, as a command's CSV header states them."""

    def __init__(self, repeats, wait_share, spread):
        self.repeats, self.wait_share, self.spread = repeats, wait_share, spread

    @classmethod
    def of(cls, res):
        """From by_tol.csv's "# flag:" line ("fewer than 5 repeats; wall above CPU by more than 5 %:
        contended; spread above 10 %")."""
        with open(os.path.join(res, "by_tol.csv")) as f:
            line = next(line for line in f if line.startswith("# flag:"))
        get = lambda pattern: float(re.search(pattern, line).group(1))  # noqa: E731
        return cls(int(get(r"fewer than (\d+) repeats")), get(r"by more than (\S+) %") / 100,
                   get(r"spread above (\S+) %") / 100)

    def flag(self, repeats, wait, spread, process=False):
        """Why a time does not count, in the commands' words; "" when it counts. `wait` is the share by
        which wall time exceeds CPU time, or for a whole process (`process`) the share of the cores other
        processes used while it ran; `repeats` None: one run by its nature (a stated exemption)."""
        why = []
        if repeats is not None and repeats < self.repeats:
            why.append(f"{repeats} repeats (< {self.repeats})")
        if wait != wait:  # NaN: not measured, so not known to count
            why.append("contention not measured")
        elif wait > self.wait_share:
            why.append(f"contended: others used {wait * 100:.0f} % of the cores" if process else
                       f"contended: wall {wait * 100:.0f} % above CPU")
        if spread != spread:
            why.append("spread not measured")
        elif spread > self.spread:
            why.append(f"spread {spread * 100:.0f} %")
        return "; ".join(why)


def benchmark(path, rule):
    """Google Benchmark's CSV (medians and _cv rows, names without "_median") as {name: row}, each row
    with its median real and CPU time in seconds, its spread and its flag under `rule`."""
    with open(path) as f:
        lines = [line for line in f if line.startswith('"BM_') or line.startswith("name,")]
    rows = {r["name"].strip('"'): r for r in csv.DictReader(lines)}
    out = {}
    for name, r in rows.items():
        if name.endswith("_cv"):
            continue
        scale = _UNIT_SCALE[r["time_unit"]]
        cv = rows.get(name + "_cv")
        real, cpu = float(r["real_time"]) / scale, float(r["cpu_time"]) / scale
        spread = float(cv["real_time"]) / scale if cv else float("nan")
        out[name] = dict(r, real_s=real, cpu_s=cpu, spread=spread,
                         flag=rule.flag(int(r["iterations"]), real / cpu - 1 if cpu > 0 else float("nan"), spread))
    return out


class Ledger:
    """Times taken and flagged per study, and what printed no time at all."""

    def __init__(self):
        self.taken, self.flagged, self.lost_items = {}, {}, []

    def count(self, study, flags):
        """Adds a study's times (their flags: "" counts)."""
        flags = list(flags)
        self.taken[study] = self.taken.get(study, 0) + len(flags)
        self.flagged[study] = self.flagged.get(study, 0) + sum(1 for f in flags if f)

    def lost(self, what, why):
        """`what` (a figure, table or sentence) printed no time: `why` (e.g. "84 of 84 times flagged")."""
        if (what, why) not in self.lost_items:
            self.lost_items.append((what, why))

    def total(self):
        return sum(self.taken.values()), sum(self.flagged.values())


def flag_words(flags):
    """The reasons among flags, one word each, in order of first appearance: "contended, spread"."""
    words = []
    for f in flags:
        for part in f.split("; "):
            w = "repeats" if "repeat" in part else part.split(":")[0].split(" ")[0]
            if w and w != "flagged" and w not in words:  # "flagged": a table's cell, no reason
                words.append(w)
    return ", ".join(words)
