#!/usr/bin/env python3
"""The paper's one timing rule (paper/timing_rule.py) and what a contended copy prints (issue #58):
Google Benchmark's medians are judged by the commands' limits (real above CPU time: contended; the
coefficient of variation: spread), a parallel run by the share of the cores others used, and a copy in
which a part lost every time carries the draft stamp and names that part on its first page, while a copy
that lost nothing carries neither.

usage: timing_rule_check.py SOURCE_DIR"""
import os
import sys
import tempfile

sys.path.insert(0, os.path.join(sys.argv[1], "paper"))
import check_paper  # noqa: E402
from macros import common, front, stability  # noqa: E402
import timing_rule  # noqa: E402

FLAG_LINE = ("# flag: why a time does not count (fewer than 5 repeats; wall above CPU by more than 5 %: contended; "
             "spread above 10 %); empty: it counts\n")
BENCH_HEAD = "name,iterations,real_time,cpu_time,time_unit,bytes_per_second,items_per_second\n"


def write(directory, name, text):
    with open(os.path.join(directory, name), "w") as f:
        f.write(text)


def bench_row(name, real_ns, cpu_ns, cv, rate=1e6):
    """A median row and its _cv row as Google Benchmark writes them (the cv scaled like a time of unit ns)."""
    return (f'"{name}",5,{real_ns},{cpu_ns},ns,,{rate}\n'
            f'"{name}_cv",5,{cv * 1e9},{cv * 1e9},ns,,0.01\n')


def scaling_csv(directory, others):
    rows = [("scalar1", 1, 4.0, 1.0, 1.0), ("simd1", 1, 1.0, 4.0, 1.0), ("simd2", 2, 0.6, 6.7, 0.83),
            ("shards2", 2, 0.62, 6.5, 0.81), ("mpi2-startup", 2, 0.4, "", "")]
    write(directory, "scaling.csv",
          "mode,cores,wall_s,traj_steps_per_s,speedup_vs_scalar,parallel_efficiency,repeats,spread,others_share\n" +
          "".join(f"{m},{c},{w},1e6,{sp},{e},5,0.02,{others}\n" for m, c, w, sp, e in rows))


def check_rules(failures):
    """The rule read from a header, benchmark flags, parallel runs and the stamp."""
    with tempfile.TemporaryDirectory() as res:
        write(res, "by_tol.csv", "scene,flag\n" + FLAG_LINE)
        rule = timing_rule.Rule.of(res)
        if (rule.repeats, rule.wait_share, rule.spread) != (5, 0.05, 0.10):
            failures.append(f"the rule read from the header: {vars(rule)}")

        write(res, "bench.csv", BENCH_HEAD + bench_row("BM_A", 1000, 990, 0.02) + bench_row("BM_B", 1840, 1000, 0.02)
              + bench_row("BM_C", 1000, 1000, 0.25))
        got = {name: r["flag"] for name, r in timing_rule.benchmark(os.path.join(res, "bench.csv"), rule).items()}
        if got["BM_A"] or not got["BM_B"].startswith("contended") or not got["BM_C"].startswith("spread 25"):
            failures.append(f"benchmark flags: {got}")

        # A parallel run counts where others used at most 5 % of the cores; one of 30 % is contended.
        for others, counts in [(0.01, True), (0.30, False)]:
            scaling_csv(res, others)
            M = common.Macros(rule)
            stability.scaling_text(res, M)
            text = M.defs["ScalingText"]
            if counts != ("untimed" not in text) or counts != (not M.ledger.lost_items):
                failures.append(f"others {others}: {text} / lost {M.ledger.lost_items}")

        # The stamp: none for a copy that lost nothing; a stamp and the list for one that lost a part.
        for lost in ([], [("figure 6, panel thesis's seven", "84 of 84 times flagged (contended)")]):
            M = common.Macros(rule)
            for what, why in lost:
                M.ledger.lost(what, why)
            write(res, "timing.csv", "n,method,flag\n")
            front.contention(res, None, M)
            stamped = bool(M.defs["ContendedStamp"]) and "84 of 84" in M.defs["ContendedNotice"]
            if stamped != bool(lost) or (not lost and M.defs["ContendedNotice"]):
                failures.append(f"lost {lost}: stamp {M.defs['ContendedStamp']!r}, notice {M.defs['ContendedNotice']!r}")


def check_figure(failures):
    # A timing figure whose times were all flagged draws its panels with words, and says what it lost.
    try:
        import make_figures
    except ImportError as e:  # no matplotlib: the figures are not drawn here at all
        print(f"figures not checked: {e}")
    else:
        with tempfile.TemporaryDirectory() as res:
            write(res, "timing.csv", "n,method,median_s,flag\n" + "".join(
                f'{n},{m},{n * 1e-7},"contended: wall 40 % above CPU"\n' for m in common.THESIS_SEVEN + ["lp-y4"]
                for n in (20000, 40000)))
            listing = []
            make_figures.timing_figure(res, res, listing)
            if len(make_figures.LOST) != 2 or "14 of 14" not in make_figures.LOST[0][1] or not listing:
                failures.append(f"a timing figure without a counted time: lost {make_figures.LOST}, drawn {listing}")


def check_paper_refusals(failures):
    # check_paper refuses a number the text promised and lost ("n/a"), and a stamp without its list.
    with tempfile.TemporaryDirectory() as build:
        os.makedirs(os.path.join(build, "generated"))
        write(build, "bodypoint.tex", "\\begin{document}\nagree within a factor of \\Gap.\n\\ContendedNotice\n")
        for gap, notice, stamp, ok in [("2.1", "", "", True), ("n/a", "", "", False),
                                       ("2.1", "\\contendednotice{1 of 2}{\\item x: y}", "", False),
                                       ("2.1", "\\contendednotice{1 of 2}{\\item x: y}", "\\contendedstamp", True)]:
            write(build, "generated/macros.tex", f"\\newcommand{{\\Gap}}{{\\ensuremath{{{gap}}}}}\n"
                  f"\\newcommand{{\\ContendedNotice}}{{{notice}}}\n\\newcommand{{\\ContendedStamp}}{{{stamp}}}\n")
            found = check_paper.numbers_lost(build)
            if ok != (not found):
                failures.append(f"check_paper on gap {gap!r}, notice {notice!r}, stamp {stamp!r}: {found}")


def main():
    failures = []
    check_rules(failures)
    check_figure(failures)
    check_paper_refusals(failures)
    if failures:
        print("\n".join(failures))
        return 1
    print("one timing rule for Google Benchmark and parallel runs; the stamp exactly when a part lost its times")
    return 0


if __name__ == "__main__":
    sys.exit(main())
