#!/usr/bin/env python3
"""Draws every figure of the bodypoint research appendix from the CSVs the drivers wrote.

usage: make_figures.py RESULTS_DIR FIGURES_DIR

Reads (all produced by `bodypoint study` and `bodypoint work-precision`, see paper/build.sh):
  d_sweep.csv, L_sweep.csv, h_sweep.csv, Kx_sweep.csv, timing.csv, force_evals.csv,
  appendix1/index.csv and appendix1/P1.*.csv, work_precision.csv
Writes one PNG per figure and figures.md, a list of the figures with the thesis figure each
one reproduces. Nothing here computes physics: it only plots what the drivers measured.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FAMILIES = {  # line style per method family, so the thesis's and our methods are told apart
    "thesis": dict(linestyle="--"),
    "rk4": dict(linestyle=":"),
    "ab4": dict(linestyle=":"),
    "lp": dict(linestyle="-"),
    "odeint": dict(linestyle="-."),
    "gsl": dict(linestyle="-."),
    "logh": dict(linestyle="-"),
    "ttl": dict(linestyle="-"),
    "ks": dict(linestyle="-"),
}


def style(method):
    for prefix, s in FAMILIES.items():
        if method.startswith(prefix):
            return s
    return {}


def read_csv(path):
    with open(path) as f:
        rows = [line for line in f if not line.startswith("#")]
    return list(csv.DictReader(rows))


def by_method(rows):
    out = {}
    for r in rows:
        out.setdefault(r["method"], []).append(r)
    return out


# Relative deviations above this mean the run diverged (the thesis's schemes and RK4 reach 1e190 at
# coarse steps); they are drawn at this ceiling so that the other curves stay readable.
DIVERGED = 1e2


def positive(values):
    """Plots on log axes drop zeros (a deviation of exactly 0) and cap diverged runs at DIVERGED."""
    return [float("nan") if not v > 0 else min(v, DIVERGED) for v in values]


def sweep_figure(rows, param, column, ylabel, title, path, methods=None):
    fig, ax = plt.subplots(figsize=(8, 5))
    for method, rs in by_method(rows).items():
        if methods and method not in methods:
            continue
        xs = [float(r[param]) for r in rs]
        ys = positive([float(r[column]) for r in rs])
        ax.plot(xs, ys, label=method, **style(method))
    ax.set_yscale("log")
    if param == "h":
        ax.set_xscale("log")
    ax.axhline(DIVERGED, color="grey", linewidth=0.5)
    ax.text(ax.get_xlim()[0], DIVERGED, " diverged", fontsize=7, va="bottom", color="grey")
    ax.set_xlabel(param)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(fontsize=6, ncol=3)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    res, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    listing = []

    def figure(name, thesis_ref, what):
        listing.append(f"| `{name}` | {thesis_ref} | {what} |")
        return os.path.join(out, name)

    thesis = ["rk4", "ab4", "thesis-euler", "thesis-verlet", "thesis-ruth3", "thesis-fr4", "thesis-y6"]
    d = read_csv(os.path.join(res, "d_sweep.csv"))
    sweep_figure(d, "d", "max_rel_dE", "max |E-E0|/|E0|", "Energy deviation against d (thesis methods)",
                 figure("d_sweep_thesis.png", "fig. 4.1-4.2", "max rel. energy deviation vs d, the thesis's seven methods"),
                 thesis)
    sweep_figure(d, "d", "max_rel_dE", "max |E-E0|/|E0|", "Energy deviation against d (all fixed-step methods)",
                 figure("d_sweep_all.png", "fig. 4.1 (extended)", "the same with the Lie-Poisson methods"))
    L = read_csv(os.path.join(res, "L_sweep.csv"))
    sweep_figure(L, "L", "max_rel_dE", "max |E-E0|/|E0|", "Energy deviation against L (d = 50)",
                 figure("L_sweep.png", "fig. 4.3-4.4", "max rel. energy deviation vs L"))
    h = read_csv(os.path.join(res, "h_sweep.csv"))
    sweep_figure(h, "h", "max_rel_dE", "max |E-E0|/|E0|", "Energy deviation against h (T = 25)",
                 figure("h_sweep_energy.png", "fig. 4.5-4.7", "max rel. energy deviation vs h"))
    sweep_figure(h, "h", "max_rel_dK2sq", "max |K2^2-K2^2_0|/K2^2_0", "|K2|^2 deviation against h",
                 figure("h_sweep_K2sq.png", "fig. 4.8-4.9", "max rel. |K2|^2 deviation vs h"))
    kx = read_csv(os.path.join(res, "Kx_sweep.csv"))
    sweep_figure(kx, "Kx", "max_rel_dK2sq", "max |K2^2-K2^2_0|/K2^2_0", "|K2|^2 deviation against Kx",
                 figure("Kx_sweep_K2sq.png", "fig. 4.10-4.11", "max rel. |K2|^2 deviation vs Kx"))

    timing = read_csv(os.path.join(res, "timing.csv"))
    fig, ax = plt.subplots(figsize=(8, 5))
    for method, rs in by_method(timing).items():
        ns = [int(r["n"]) for r in rs]
        ax.plot(ns, [float(r["median_s"]) for r in rs], label=method, **style(method))
        ax.fill_between(ns, [float(r["min_s"]) for r in rs], [float(r["max_s"]) for r in rs], alpha=0.15)
    ax.set_yscale("log")
    ax.set_xlabel("n (steps)")
    ax.set_ylabel("run time of the step loop [s] (median, min-max band)")
    ax.set_title("Run time against n (h = 1e-4, table 3.1)")
    ax.legend(fontsize=6, ncol=3)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(figure("timing.png", "fig. 4.12-4.13", "run time vs n, median of repeats"), dpi=120)
    plt.close(fig)

    wp_path = os.path.join(res, "work_precision.csv")
    if os.path.exists(wp_path):
        wp = read_csv(wp_path)
        for scene in sorted({r["scene"] for r in wp}):
            fig, ax = plt.subplots(figsize=(8, 5))
            for method, rs in by_method([r for r in wp if r["scene"] == scene]).items():
                pts = [(float(r["wall_s"]), float(r["err_rel"])) for r in rs if float(r["err_rel"]) > 0]
                pts = [(t, e) for t, e in pts if e == e and e < 1]
                if pts:
                    ax.plot([p[0] for p in pts], [p[1] for p in pts], marker=".", label=method, **style(method))
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("run time [s] (median)")
            ax.set_ylabel("final-position error |R - R_ref|/|R_ref|")
            ax.set_title(f"Work-precision: scene '{scene}'")
            ax.legend(fontsize=5, ncol=4)
            ax.grid(True, which="both", alpha=0.3)
            fig.tight_layout()
            fig.savefig(figure(f"work_precision_{scene}.png", "new", f"error vs run time, scene {scene}"), dpi=120)
            plt.close(fig)

    index = read_csv(os.path.join(res, "appendix1", "index.csv"))
    fig, axes = plt.subplots(5, 6, figsize=(18, 14))
    for ax, row in zip(axes.flat, index):
        ax.set_title(f"P1.{row['figure']}", fontsize=8)
        if row["status"] != "ok":
            ax.text(0.5, 0.5, "skipped:\nD = mJ - B^2 <= 0", ha="center", va="center", fontsize=8)
            ax.set_axis_off()
            continue
        traj = read_csv(os.path.join(res, "appendix1", row["file"]))
        ax.plot([float(r["Rx"]) for r in traj], [float(r["Ry"]) for r in traj], linewidth=0.8)
        ax.plot([0], [0], "r*")
        ax.tick_params(labelsize=6)
    fig.tight_layout()
    fig.savefig(figure("appendix1_trajectories.png", "appendix 1, fig. P1.1-P1.30",
                       "trajectories (x, y) of the 30 parameter sets, thesis-euler"), dpi=100)
    plt.close(fig)

    with open(os.path.join(out, "figures.md"), "w") as f:
        f.write("| figure | reproduces | content |\n|---|---|---|\n" + "\n".join(listing) + "\n")
    print(f"wrote {len(listing)} figures to {out}")


if __name__ == "__main__":
    main()
