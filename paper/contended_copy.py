"""The paper as a fully contended machine would build it: every time of a results directory flagged.

A build on a busy machine flags some times (paper/timing_rule.py) and the paper then prints other words,
a draft stamp and a list of what lost every time after the abstract (make_macros.py's ContendedNotice): pages
whose layout the idle build never shows. `flag_every_time(src, dst)` copies `src` with every time flagged
(each CSV's flag column or share of the cores others used, the (d, L) map's share, and Google
Benchmark's medians with wall time twice CPU time), the worst case of
that layout, so that check_paper.py's `contended` check builds and checks it on any machine, idle or not.
"""
import csv
import io
import os
import shutil

# The words a command writes in a flag column for a time taken while the thread waited for a core
# (experiments/cli/stopwatch.cpp).
CONTENDED = "contended: wall 50 % above CPU"


def _row(cells):
    out = io.StringIO()
    csv.writer(out, lineterminator="").writerow(cells)
    return out.getvalue()


# The share of the cores other processes used while a whole process ran (scripts/contention.sh), where a
# CSV states it in place of a flag (scaling.csv, map_scale.csv) and in dL_map_seconds.txt.
OTHERS_SHARE = "0.5"


def _flag_column(lines):
    """A command's CSV (comment lines, a header, rows) with every row's flag set, or the share of the cores
    others used; unchanged without either."""
    head = next((i for i, line in enumerate(lines) if not line.startswith("#")), None)
    if head is None:
        return lines
    columns = next(csv.reader([lines[head]]))
    marks = {columns.index(c): value for c, value in [("flag", CONTENDED), ("others_share", OTHERS_SHARE)] if c in columns}
    if not marks:
        return lines
    rows = []
    for line in lines[head + 1:]:
        cells = next(csv.reader([line])) if line and not line.startswith("#") else None
        if cells and len(cells) == len(columns):
            for k, value in marks.items():
                cells[k] = value
            line = _row(cells)
        rows.append(line)
    return lines[:head + 1] + rows


def _contend_benchmark(lines):
    """Google Benchmark's medians (bench_steps.csv, bench_batch.csv) with real time twice the CPU time."""
    columns, out = None, []
    for line in lines:
        if line.startswith("name,"):
            columns = next(csv.reader([line]))
        elif columns and line.startswith('"BM_') and not line.split(",", 1)[0].endswith('_cv"'):
            # Split, not re-quoted: paper/timing_rule.py finds the rows by their quoted names.
            cells = line.split(",")
            cells[columns.index("real_time")] = repr(2 * float(cells[columns.index("cpu_time")]))
            line = ",".join(cells)
        out.append(line)
    return out


def flag_every_time(src, dst):
    """Copies the results directory `src` to `dst` (replaced) with every time flagged."""
    shutil.rmtree(dst, ignore_errors=True)
    shutil.copytree(src, dst)
    seconds = os.path.join(dst, "dL_map_seconds.txt")
    if os.path.exists(seconds):
        with open(seconds) as f:
            fields = f.read().split()
        with open(seconds, "w") as f:
            f.write(" ".join(fields[:2] + [OTHERS_SHARE]) + "\n")
    for name in sorted(os.listdir(dst)):
        path = os.path.join(dst, name)
        if not name.endswith(".csv"):
            continue
        with open(path) as f:
            lines = f.read().splitlines()
        lines = _contend_benchmark(lines) if name.startswith("bench_") else _flag_column(lines)
        with open(path, "w") as f:
            f.write("\n".join(lines) + "\n")
