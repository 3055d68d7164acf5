#!/usr/bin/env python3
"""Draws every figure of the bodypoint research appendix, as vector PDF, from the CSVs the drivers wrote.

usage: make_figures.py [--only scattering] RESULTS_DIR FIGURES_DIR

Reads (all written by paper/build.sh through `bodypoint study`, `bodypoint work-precision`):
  {d,L,h,Kx}_sweep.csv and published_{d,L,h,Kx}_sweep.csv, timing.csv, appendix1/index.csv and
  appendix1/P1.*.csv, work_precision.csv, by_tol.csv, far_field_resonances.csv (bench/far_field.py), and
  dL_map.csv, scattering.csv and long_time.csv when present
Writes fig_*.pdf and figures.md (which thesis figure each one stands for). Nothing here computes
physics: it only draws what the drivers measured.
"""
import csv
import math
import os
import re
import sys

from catalogue import families, family, load as load_catalogue
from macros.common import num
import map_rule
import timing_rule

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

plt.rcParams.update({"font.size": 8, "axes.titlesize": 8, "legend.fontsize": 7, "xtick.labelsize": 7,
                     "ytick.labelsize": 7, "figure.dpi": 100, "pdf.fonttype": 42, "savefig.bbox": "tight"})

THESIS_SEVEN = ["thesis-euler", "thesis-verlet", "thesis-ruth3", "thesis-fr4", "thesis-y6", "rk4", "ab4"]
# Families of the work-precision figures, in drawing order, with a colour each; a family the catalogue
# adds is drawn after them in the next free colour (family_colours).
FAMILIES = [("thesis's seven", "tab:red"), ("Lie-Poisson", "tab:blue"), ("time-transformed", "tab:green"),
            ("KS", "tab:purple"), ("Kepler split", "tab:cyan"), ("Boost.Odeint", "tab:orange"), ("GSL", "tab:brown"),
            ("logH+BS", "tab:pink"), ("SUNDIALS", "navy")]
SPARE_COLOURS = ["tab:olive", "tab:gray", "black", "gold"]


def family_colours():
    """FAMILIES, then every other family of the catalogue with a colour of its own."""
    named = [f for f, _ in FAMILIES]
    extra = [f for f in families() if f not in named]
    return FAMILIES + list(zip(extra, SPARE_COLOURS))
# Deviations above this mean the run diverged (the thesis's schemes reach 1e190 at coarse steps); they
# are drawn at this ceiling so the other curves stay readable.
DIVERGED = 1e2
# Width of a figure spanning the text, in inches (the article's text block is 6.3 in).
WIDE = 6.3
# The text block of paper/bodypoint.tex (a4paper, margin=2.3cm), in inches: what \textwidth and
# \textheight are when save() checks a figure's text at the size it is printed.
TEXTWIDTH = (21.0 - 2 * 2.3) / 2.54
TEXTHEIGHT = (29.7 - 2 * 2.3) / 2.54
# No text of a figure is smaller than this at print size (points).
MIN_PRINT_PT = 7.0




def read_csv(path):
    with open(path) as f:
        rows = [line for line in f if not line.startswith("#")]
    return list(csv.DictReader(rows))


def by_method(rows):
    out = {}
    for r in rows:
        out.setdefault(r["method"], []).append(r)
    return out


def scenes_of(rows):
    """The scenes of a driver's CSV in the order it ran them."""
    return list(dict.fromkeys(r["scene"] for r in rows))


def capped(v, cap=DIVERGED):
    """Log axes drop zeros (a deviation of exactly 0); diverged runs are drawn at `cap`."""
    return float("nan") if not v > 0 else min(v, cap)


def save(fig, path, listing, what, width=1.0, max_height=None):
    """Writes the figure; `width` is the share of \\textwidth it is included at (and `max_height` the
    share of \\textheight that may limit it, as keepaspectratio does). Stops the build when any of its
    text would print smaller than MIN_PRINT_PT."""
    fig.canvas.draw()
    box = fig.get_tightbbox(fig.canvas.get_renderer())  # inches, as savefig's bbox "tight" crops
    scale = width * TEXTWIDTH / box.width
    if max_height is not None:
        scale = min(scale, max_height * TEXTHEIGHT / box.height)
    sizes = [t.get_fontsize() for t in fig.findobj(matplotlib.text.Text) if t.get_visible() and t.get_text().strip()]
    if sizes and min(sizes) * scale < MIN_PRINT_PT - 0.05:
        sys.exit(f"make_figures.py: {os.path.basename(path)} prints text at {min(sizes) * scale:.1f} pt "
                 f"(below {MIN_PRINT_PT:g} pt at print size)")
    fig.savefig(path)
    plt.close(fig)
    listing.append((os.path.basename(path), what))


# Distinct colours for the highlighted curves of a panel; the rest grey. The thesis's seven keep one
# colour each in every panel, so that a method is the same line across panels.
PANEL_COLOURS = ["tab:blue", "tab:red", "tab:green", "tab:orange", "tab:purple", "tab:brown"]
SEVEN_COLOURS = {"rk4": "tab:red", "ab4": "tab:orange", "thesis-euler": "tab:blue", "thesis-verlet": "tab:cyan",
                 "thesis-ruth3": "tab:green", "thesis-fr4": "tab:olive", "thesis-y6": "tab:purple"}


def median(values):
    v = sorted(x for x in values if math.isfinite(x))
    return v[len(v) // 2] if v else float("inf")


def best_first(rows, column, methods):
    """methods ordered by the median of their capped deviations, smallest first."""
    groups = by_method(rows)
    return sorted((m for m in methods if m in groups), key=lambda m: median(capped(num(r[column])) for r in groups[m]))


def sweep_panel(ax, rows, param, column, families, title):
    """One panel: for each (methods, k, label) of `families`, its k best methods (smallest median
    deviation) in colour and named, the others thin and grey under one legend entry."""
    groups = by_method(rows)
    colour = iter(PANEL_COLOURS)
    for methods, k, other_label in families:
        ranked = best_first(rows, column, methods)
        for i, m in enumerate(ranked):
            xs = [num(r[param]) for r in groups[m]]
            ys = [capped(num(r[column])) for r in groups[m]]
            if i < k:
                ax.plot(xs, ys, label=m, color=SEVEN_COLOURS.get(m) or next(colour), linewidth=1.1,
                        linestyle="--" if m.startswith("thesis-") else "-", zorder=3)
            else:
                ax.plot(xs, ys, color="0.65", linewidth=0.5, zorder=2,
                        label=f"{other_label} ({len(ranked) - k})" if i == k else None)
    ax.set_yscale("log")
    if param == "h":
        ax.set_xscale("log")
    ax.axhline(DIVERGED, color="grey", linewidth=0.4)
    ax.set_xlabel(param)
    ax.set_title(title)
    # Below the panel, one column, so that no curve is hidden and no label runs into the next panel's.
    ax.legend(ncol=1, loc="upper center", bbox_to_anchor=(0.5, -0.22), frameon=False)


def thesis_families():
    """The thesis's seven as two families: RK4 and AB4 both named, the best two drift/kick schemes."""
    return [(["rk4", "ab4"], 2, "other"), ([m for m in THESIS_SEVEN if m.startswith("thesis-")], 2, "other drift/kick")]


def lie_family(rows):
    return [(sorted({r["method"] for r in rows if r["method"].startswith("lp-")}), 4, "other exact splittings")]


def sweep_figures(res, figs, listing):
    # Each thesis figure with what it plotted: the energy against d, L and h, |K2|^2 against h and Kx.
    thesis_figs = [("d", "max_rel_dE", "4.1-4.2", "fig_sweep_d"), ("L", "max_rel_dE", "4.3-4.4", "fig_sweep_L"),
                   ("h", "max_rel_dE", "4.5-4.7", "fig_sweep_h"), ("h", "max_rel_dK2sq", "4.8-4.9", "fig_k2sq_h"),
                   ("Kx", "max_rel_dK2sq", "4.10-4.11", "fig_sweep_Kx")]
    for param, column, tfig, name in thesis_figs:
        rows = read_csv(os.path.join(res, f"{param}_sweep.csv"))
        published = read_csv(os.path.join(res, f"published_{param}_sweep.csv"))
        fig, axes = plt.subplots(1, 3, figsize=(WIDE, 2.9), sharey=True)
        sweep_panel(axes[0], published, param, column, thesis_families(), "as published (code, harness)")
        sweep_panel(axes[1], rows, param, column, thesis_families(), "the same seven, corrected")
        sweep_panel(axes[2], rows, param, column, lie_family(rows), "exact Lie-Poisson, corrected")
        what = "energy" if column == "max_rel_dE" else "$|K_2|^2$"
        axes[0].set_ylabel(f"max relative deviation of {what}")
        save(fig, os.path.join(figs, f"{name}.pdf"), listing, f"thesis fig. {tfig}: max relative {what} deviation against {param}")


# What a figure lost to the timing rules: (what, why) per panel that has no counted time; main() writes
# them to FIGURES_DIR/lost.csv for make_macros.py, which stamps the copy and lists them on its first page.
LOST = []


def lost(ax, what, flags):
    """An empty panel: every time it would draw was flagged (or none was taken). The panel says so in
    words instead of showing empty automatic axes."""
    flags = [f for f in flags]
    n_flagged = sum(1 for f in flags if f)
    why = (f"{n_flagged} of {len(flags)} times flagged ({timing_rule.flag_words(flags)})" if n_flagged
           else "no time taken")
    ax.set_xticks([])
    ax.set_yticks([])
    ax.text(0.5, 0.5, "no counted time:\n" + why.replace(" (", "\n("), ha="center", va="center",
            transform=ax.transAxes, fontsize=8)
    LOST.append((what, why))


def timing_figure(res, figs, listing):
    """Two panels of at most five named lines: the thesis's seven (the four its claims name in colour)
    and four exact splittings of rising order."""
    rows = read_csv(os.path.join(res, "timing.csv"))
    groups = by_method(rows)
    panels = [("thesis's seven", ["thesis-euler", "thesis-fr4", "thesis-y6", "rk4", "ab4"], ["thesis-verlet", "thesis-ruth3"]),
              ("exact Lie-Poisson", ["lp-verlet", "lp-y4", "lp-kl6", "lp-kl8"], [])]
    fig, axes = plt.subplots(1, 2, figsize=(WIDE * 2 / 3, 2.9))  # a scale per panel
    for ax, (title, named, grey) in zip(axes, panels):
        colour = iter(PANEL_COLOURS)
        mine = [r for m in grey + named for r in groups.get(m, [])]
        if not any(not r.get("flag") for r in mine):
            lost(ax, "figure~\\ref{fig:timing}, panel " + title, [r.get("flag", "") for r in mine])
            continue
        for m in grey + named:
            rs = [r for r in groups.get(m, []) if not r.get("flag")]  # a flagged time is not drawn
            xs, ys = [num(r["n"]) for r in rs], [num(r["median_s"]) * 1e3 for r in rs]
            if m in grey:
                ax.plot(xs, ys, color="0.65", linewidth=0.5, label=f"other drift/kick ({len(grey)})" if m == grey[0] else None)
            else:
                ax.plot(xs, ys, label=m, color=SEVEN_COLOURS.get(m) or next(colour), linewidth=1.0,
                        linestyle="--" if m.startswith("thesis-") else "-")
        ax.set_xlabel("number of steps n")
        ax.set_title(title)
        ax.legend(ncol=1, loc="upper left", frameon=False)  # the lines rise to the right: the upper left is empty
    axes[0].set_ylabel("median run time [ms]")
    fig.tight_layout()
    save(fig, os.path.join(figs, "fig_timing.pdf"), listing, "thesis fig. 4.12-4.13: run time against n", width=0.67)


def appendix_figure(res, figs, listing):
    index = read_csv(os.path.join(res, "appendix1", "index.csv"))
    # Six rows of five, a full page: each panel with its own ticks (the sets span very different scales).
    fig, axes = plt.subplots(6, 5, figsize=(WIDE, 8.4))
    for ax, row in zip(axes.flat, index):
        ax.tick_params(labelsize=7, length=2, pad=1)
        ax.locator_params(nbins=3)
        label = f"P1.{row['figure']}"
        if not row["file"]:
            ax.set_xticks([])
            ax.set_yticks([])
            ax.text(0.5, 0.5, "D <= 0:\nnot run", ha="center", va="center", fontsize=7, transform=ax.transAxes)
        else:
            traj = read_csv(os.path.join(res, "appendix1", row["file"]))
            xs = [num(r["Rx"]) for r in traj]
            ys = [num(r["Ry"]) for r in traj]
            ok = [(x, y) for x, y in zip(xs, ys) if math.isfinite(x) and math.isfinite(y) and abs(x) < 1e4 and abs(y) < 1e4]
            if ok:
                ax.plot([p[0] for p in ok], [p[1] for p in ok], linewidth=0.7)
            ax.plot([0], [0], "k.", markersize=3)
            if len(ok) < len(xs):
                label += " (leaves)"
            if row["outcome"] != "ok":
                label += f" ({row['outcome']})"
        ax.set_title(label, fontsize=7, pad=2)
    fig.supxlabel("x", fontsize=8)
    fig.supylabel("y", fontsize=8)
    fig.tight_layout(pad=0.4, h_pad=0.6, w_pad=0.4)
    save(fig, os.path.join(figs, "fig_appendix1.pdf"), listing,
         "thesis appendix 1 (fig. P1.1-P1.30): trajectories in the (x, y) plane, thesis-euler, h = 1e-4",
         max_height=0.86)


def pareto(points):
    """Points (time, error, label) not dominated by a faster and more accurate one, by time."""
    front, best = [], float("inf")
    for t, e, lab in sorted(points):
        if e < best:
            front.append((t, e, lab))
            best = e
    return front


def place_labels(ax, labels, fontsize=7):
    """Annotates each (x, y, text, colour) beside its point, moving a label down (then up) in steps of a line
    until its box overlaps no label placed before it (labels of neighbouring fronts collided) and stays
    inside the axes (a label below them printed over the tick labels)."""
    ax.autoscale_view()
    to_pt = 72.0 / ax.figure.dpi
    char_w, line_h = 0.62 * fontsize, 1.25 * fontsize  # points (DejaVu Sans averages 0.6 em a character)
    placed = []  # boxes (x0, y0, x1, y1) in points
    frame = ax.get_window_extent()
    right_edge, bottom, top = frame.x1 * to_pt, frame.y0 * to_pt, frame.y1 * to_pt
    shifts = [3.0 - k * line_h for k in range(12)] + [3.0 + k * line_h for k in range(1, 12)]
    for x, y, text, colour in labels:
        px, py = (v * to_pt for v in ax.transData.transform((x, y)))
        width = char_w * len(text)
        # Left of the point where the label would cross the axes' right edge (it widened the figure).
        dx = 3.0 if px + 3.0 + width <= right_edge else -3.0 - width
        inside = [dy for dy in shifts if py + dy >= bottom and py + dy + line_h <= top] or [3.0]
        dy = inside[0]
        for candidate in inside:
            box = (px + dx, py + candidate, px + dx + width, py + candidate + line_h)
            if not any(box[0] < b[2] and b[0] < box[2] and box[1] < b[3] and b[1] < box[3] for b in placed):
                dy = candidate
                break
        placed.append((px + dx, py + dy, px + dx + width, py + dy + line_h))
        ax.annotate(text, (x, y), fontsize=fontsize, color=colour, xytext=(dx, dy), textcoords="offset points")


def reference_errors(path):
    """{scene: relative error of its long-double reference}, from work-precision's CSV header."""
    out = {}
    with open(path) as f:
        for line in f:
            m = re.match(r"# reference (\S+): .* \(relative ([^,)\s]+)", line)
            if m:
                out[m.group(1)] = float(m.group(2))
    return out


def work_precision_figures(res, figs, listing):
    rows = read_csv(os.path.join(res, "work_precision.csv"))
    unresolved = reference_errors(os.path.join(res, "work_precision.csv"))
    scenes = scenes_of(rows)
    for scene in scenes:
        fig, ax = plt.subplots(figsize=(WIDE / 2, 2.8))
        labels = []  # (time, error, text, colour) of the methods named on the fronts
        drawn = False
        for fam, colour in family_colours():
            pts = [(num(r["wall_s"]) * 1e3, num(r["err_rel"]), r["method"]) for r in rows
                   if r["scene"] == scene and family(r["method"]) == fam and not r.get("flag")]  # flagged: no time
            pts = [p for p in pts if p[0] > 0 and 0 < p[1] < 1]
            front = pareto(pts)
            if not front:
                continue
            drawn = True
            ax.step([p[0] for p in front], [p[1] for p in front], where="post", color=colour, label=fam, linewidth=1)
            ax.plot([p[0] for p in front], [p[1] for p in front], ".", color=colour, markersize=3)
            # Label the methods that hold the longest stretches of the front (at most three).
            counts = {}
            for p in front:
                counts[p[2]] = counts.get(p[2], 0) + 1
            for lab in sorted(counts, key=lambda k: -counts[k])[:3]:
                mine = [p for p in front if p[2] == lab]
                t, e, _ = mine[len(mine) // 2]  # the middle of its stretch: labels of one front spread out
                labels.append((t, e, lab, colour))
        ax.set_title(f"scene {scene}: Pareto front per family")
        if not drawn:  # every time of the scene flagged: the panel says so
            lost(ax, f"the work-precision figure of scene {scene}", [r.get("flag", "") for r in rows if r["scene"] == scene])
            save(fig, os.path.join(figs, f"fig_wp_{scene}.pdf"), listing, f"work-precision on scene {scene}", width=0.49)
            continue
        ax.set_xscale("log")
        ax.set_yscale("log")
        if scene in unresolved:  # errors the reference cannot resolve: greyed
            ax.axhspan(ax.get_ylim()[0], unresolved[scene], color="0.88", zorder=0, linewidth=0)
        place_labels(ax, labels)
        ax.set_xlabel("run time [ms]")
        ax.set_ylabel("final-state error max(|dR|/|R|, |dv|/|v|)")
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2, frameon=False)  # off the labels
        save(fig, os.path.join(figs, f"fig_wp_{scene}.pdf"), listing, f"work-precision on scene {scene}", width=0.49)


def tol_ticks(ax, tols):
    """A tick at every requested TOL, labelled at most three times (the ends and the middle): six panels
    share the text width, and five labels of 10^-k overlapped there."""
    ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
    ax.set_xticks(tols)
    every = max(1, math.ceil((len(tols) - 1) / 2))
    ax.set_xticklabels([f"$10^{{{round(math.log10(t))}}}$" if i % every == 0 or i == len(tols) - 1 else ""
                        for i, t in enumerate(tols)])


def by_tol_figure(res, figs, listing):
    rows = read_csv(os.path.join(res, "by_tol.csv"))
    scenes = scenes_of(rows)
    fig, axes = plt.subplots(1, len(scenes), figsize=(WIDE, 2.2), sharey=True, squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        sr = [r for r in rows if r["scene"] == scene and r["kind"] in ("auto", "at-tol")]
        for name in sorted({r["method"] if r["kind"] == "at-tol" else "auto" for r in sr}):
            rs = [r for r in sr if (r["kind"] == "auto" and name == "auto") or (r["kind"] == "at-tol" and r["method"] == name)]
            ax.plot([num(r["tol"]) for r in rs], [capped(num(r["err"])) for r in rs], "o-" if name == "auto" else ".--",
                    label=name, markersize=3, linewidth=1.2 if name == "auto" else 0.7)
        lo = min(num(r["tol"]) for r in sr)
        hi = max(num(r["tol"]) for r in sr)
        ax.plot([lo, hi], [lo, hi], color="grey", linewidth=0.5)
        ax.set_xscale("log")
        ax.set_yscale("log")
        tol_ticks(ax, sorted({num(r["tol"]) for r in sr}))
        ax.set_title(scene)
        ax.set_xlabel("requested TOL")
    axes[0][0].set_ylabel("delivered error")
    handles, names = axes[0][0].get_legend_handles_labels()
    fig.tight_layout()
    # Below the panels and their axis labels, off the data.
    fig.legend(handles, names, loc="upper center", bbox_to_anchor=(0.5, -0.01), ncol=4, frameon=False)
    save(fig, os.path.join(figs, "fig_by_tol.pdf"), listing, "delivered error against requested TOL")


def far_field_figure(res, figs, listing):
    """The far pass's error against the spin angle per step (bench/far_field.py), with the half and
    whole turns of the spin marked: where a step longer than the cap meets its resonances."""
    rows = read_csv(os.path.join(res, "far_field_resonances.csv"))
    fig, ax = plt.subplots(figsize=(WIDE / 2, 2.4))
    for method, colour in zip(dict.fromkeys(r["method"] for r in rows), PANEL_COLOURS):
        rs = [r for r in rows if r["method"] == method]
        ax.plot([num(r["spin_angle"]) for r in rs], [capped(num(r["err"])) for r in rs], ".-", color=colour,
                label=method, markersize=3, linewidth=0.8)
    for k, label in [(1, r"$\pi$"), (2, r"$2\pi$"), (4, r"$4\pi$")]:
        ax.axvline(k * math.pi, color="grey", linewidth=0.5, linestyle=":")
        ax.annotate(label, (k * math.pi, 1.0), xycoords=("data", "axes fraction"), ha="center", va="bottom",
                    fontsize=7)
    ax.set_yscale("log")
    ax.set_xscale("log")  # the splittings below a few radians per step, far-ip up to a hundred
    ax.set_xlabel("spin angle per step [rad]")
    ax.set_ylabel("final-state error max(|dR|/|R|, |dv|/|v|)")
    ax.legend(loc="lower right")
    save(fig, os.path.join(figs, "fig_far_field.pdf"), listing, "far pass: error against the spin angle per step",
         width=0.55)


def long_time_figure(res, figs, listing):
    """Bound orbits over many periods (study --name long-time): the largest energy error so far on the
    Kepler ellipse and on the two-centre orbit, |K2|^2 of the spinning body, the Kepler ellipse's phase
    error. Skipped when the study was not run."""
    path = os.path.join(res, "long_time.csv")
    if not os.path.exists(path):
        return
    rows = read_csv(path)
    methods = [m for m in dict.fromkeys(r["method"] for r in rows) if m != "lp-kl8"]
    colours = dict(zip(methods, PANEL_COLOURS + ["navy", "tab:olive", "tab:cyan"]))  # GSL, SUNDIALS: optional
    panels = [("kepler", "max_rel_dE", "Kepler ellipse: energy", r"max $|\Delta E/E|$ so far"),
              ("two-centres", "max_rel_dE", "two centres: energy", r"max $|\Delta E/E|$ so far"),
              ("spinning", "rel_dK2sq", r"spinning body: $|K_2|^2$", r"$|\Delta |K_2|^2| / |K_2|^2$"),
              ("kepler", "phase_err", "Kepler ellipse: phase", "mean anomaly error [rad]")]
    fig, axes = plt.subplots(2, 2, figsize=(WIDE, 4.6))
    for ax, (scene, column, title, ylabel) in zip(axes.flat, panels):
        for m in methods:
            rs = [r for r in rows if r["scene"] == scene and r["method"] == m]
            # Not capped at DIVERGED: a phase error grows past it (10^7 rad and more) and its slope is the result.
            ax.plot([num(r["periods"]) for r in rs], [capped(num(r[column]), math.inf) for r in rs], ".-",
                    color=colours[m], label=m, markersize=3, linewidth=0.8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(title)
        ax.set_ylabel(ylabel)
    for ax in axes[1]:
        ax.set_xlabel("periods")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(len(methods), 4), bbox_to_anchor=(0.5, -0.06))
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    save(fig, os.path.join(figs, "fig_long_time.pdf"), listing,
         "bound orbits over many periods: energy, |K2|^2 and phase errors against time")


def map_figure(res, figs, listing):
    """The (d, L) stability map (bodypoint study --name dL-map): a heat map of log10 max relative energy
    deviation per fixed-step method whose map is not uniform (map_rule.py; the others are rows of the paper's
    table); cells whose run is not ok (diverged, collision) in black."""
    path = os.path.join(res, "dL_map.csv")
    if not os.path.exists(path):
        return
    rows = read_csv(path)
    ds = sorted({num(r["d"]) for r in rows})
    Ls = sorted({num(r["L"]) for r in rows})
    groups = by_method(rows)
    # A uniform map is a row of the paper's table (map_rule.py), not a panel.
    methods = [m for m in groups if not map_rule.uniform(groups[m])]
    if not methods:
        return
    cols = min(6, len(methods))
    nrows = (len(methods) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(WIDE, 1.25 * nrows + 0.5), sharex=True, sharey=True, squeeze=False)
    cmap = plt.get_cmap("viridis").copy()
    cmap.set_bad("black")
    image = None
    for ax, m in zip(axes.flat, methods):
        grid = [[float("nan")] * len(ds) for _ in Ls]
        for r in groups[m]:
            v = num(r["max_rel_dE"])
            ok = r["outcome"] == "ok" and v > 0
            grid[Ls.index(num(r["L"]))][ds.index(num(r["d"]))] = math.log10(v) if ok else float("nan")
        image = ax.pcolormesh(ds, Ls, grid, cmap=cmap, vmin=-16, vmax=0, shading="nearest")
        ax.grid(False)
        ax.set_title(m, pad=2, fontsize=7)
    for ax in axes.flat[len(methods):]:
        ax.axis("off")
    for ax in axes[-1]:
        ax.set_xlabel("d")
    for ax in axes[:, 0]:
        ax.set_ylabel("L")
    fig.colorbar(image, ax=axes, shrink=0.9, label="log10 max |dE/E|")  # black: not ok (the caption says so)
    save(fig, os.path.join(figs, "fig_dL_map.pdf"), listing,
         "the (d, L) stability map, a panel per fixed-step method whose map is not uniform")


def scattering_figure(res, figs, listing):
    """bodypoint study --name scattering: per series the band of the deflection theta(b) over the helix's
    arrival phase (a material point's has none), the beam's differential cross-section summed over every
    branch with its quadrature error beside Rutherford's for the guiding centre's mass (grey), and the
    band of the closest approach r_min(b); rainbows located per phase as open circles."""
    path = os.path.join(res, "scattering.csv")
    if not os.path.exists(path):
        return
    rows = read_csv(path)
    xs = read_csv(os.path.join(res, "scattering_cross_section.csv"))
    rainbows = read_csv(os.path.join(res, "scattering_rainbows.csv"))
    series = list(dict.fromkeys(r["series"] for r in rows))
    material = [n for n in series if n == "B=0" or n.startswith("B=0 ")]
    groups = [("material point", material), ("spinning body", [n for n in series if n not in material])]
    fig, grid = plt.subplots(2, 3, figsize=(WIDE, 4.8))
    cmap = plt.get_cmap("tab10")
    for axes, (title, names) in zip(grid, groups):
        for ax in axes:
            ax.set_title(title)
        for i, name in enumerate(names):
            rs = [r for r in rows if r["series"] == name and r["failure"] == "" and num(r["theta"]) > 0]
            if not rs:
                continue
            colour = cmap(i % 10)
            dashed = i > 0 and title == "material point"  # the second method on the same curve
            style = dict(color=colour, linewidth=0.9, label=name, linestyle="--" if dashed else "-")
            bs = sorted({num(r["b"]) for r in rs})
            for col, ax in (("theta", axes[0]), ("r_min", axes[2])):
                at = {b: [num(r[col]) for r in rs if num(r["b"]) == b] for b in bs}
                lo, hi = [min(at[b]) for b in bs], [max(at[b]) for b in bs]
                ax.plot(bs, hi, **style)
                if lo != hi:
                    ax.plot(bs, lo, color=colour, linewidth=0.6)
                    ax.fill_between(bs, lo, hi, color=colour, alpha=0.2, linewidth=0)
            rb = [r for r in rainbows if r["series"] == name and r["kind"] == "max" and num(r["theta"]) > 0]
            axes[0].plot([num(r["b"]) for r in rb], [num(r["theta"]) for r in rb], "o", markersize=3,
                         markerfacecolor="none", color=colour)
            bins = [r for r in xs if r["series"] == name and r["covered"] == "1" and num(r["dsigma_domega"]) > 0]
            axes[1].errorbar([num(r["theta"]) for r in bins], [num(r["dsigma_domega"]) for r in bins],
                             yerr=[min(num(r["quadrature_error"]), 0.9 * num(r["dsigma_domega"])) for r in bins],
                             fmt="o", markersize=2, capsize=1.5, **style)
            if i == 0:
                axes[1].plot([num(r["theta"]) for r in bins], [num(r["dsigma_rutherford_gc"]) for r in bins],
                             color="grey", linewidth=2.5, alpha=0.35, zorder=0, label="Rutherford (guiding centre)")
        for ax, (xl, yl) in zip(axes, [(r"impact parameter $b$", r"deflection $\theta$ [rad]"),
                                       (r"deflection $\theta$ [rad]", r"$d\sigma/d\Omega$ (beam)"),
                                       (r"impact parameter $b$", r"closest approach $r_{\min}$")]):
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(xl)
            ax.set_ylabel(yl)
        handles, labels = axes[1].get_legend_handles_labels()
        if title == "material point":  # two lines: inside, where the curves are not
            axes[2].legend(*axes[0].get_legend_handles_labels(), loc="upper left", frameon=False)
            axes[1].legend(loc="lower left", frameon=False)
        else:  # every series: below the figure, off the curves
            fig.legend(handles, labels, loc="lower center", ncol=4, frameon=False, bbox_to_anchor=(0.5, 0.0))
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    save(fig, os.path.join(figs, "fig_scattering.pdf"), listing,
         "scattering: deflection function, differential cross-section and closest approach per series")


def l_cost_figure(res, figs, listing):
    """bodypoint study --name L (L_cost.csv): what an encounter at its limit L -> infinity costs against its
    start distance, auto at tol 1e-8 with every evaluation of the answer (its run from 2L included), the runs
    with far legs marked, beside the thesis's fixed step's evaluations to the same departure."""
    path = os.path.join(res, "L_cost.csv")
    if not os.path.exists(path):
        return
    rows = [r for r in read_csv(path) if r["failure"] == ""]
    fig, ax = plt.subplots(figsize=(WIDE / 2, 2.4))
    ls = [num(r["L"]) for r in rows]
    ax.plot(ls, [num(r["fixed_step_evals"]) for r in rows], ".-", color="tab:red", markersize=3, linewidth=0.8,
            label=r"thesis's step $h = 10^{-4}$")
    ax.plot(ls, [num(r["force_evals"]) for r in rows], ".-", color="tab:blue", markersize=3, linewidth=0.8,
            label=r"auto, tol $10^{-8}$, whole call")
    legs = [r for r in rows if r["far_legs"] == "1"]
    ax.plot([num(r["L"]) for r in legs], [num(r["force_evals"]) for r in legs], "o", color="tab:blue", markersize=4,
            markerfacecolor="none", label="with far legs")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("start distance $L$")
    ax.set_ylabel("force evaluations")
    ax.legend(loc="upper left", frameon=False)
    save(fig, os.path.join(figs, "fig_L_cost.pdf"), listing, "an encounter's cost against its start distance",
         width=0.55)


def main():
    args = sys.argv[1:]
    only = None
    if len(args) == 4 and args[0] == "--only" and args[1] == "scattering":
        only, args = args[1], args[2:]
    if len(args) != 2:
        sys.exit("usage: make_figures.py [--only scattering] RESULTS_DIR FIGURES_DIR")
    res, figs = args
    os.makedirs(figs, exist_ok=True)
    listing = []
    if only == "scattering":  # scripts/scattering-study.sh: that study's figure alone
        scattering_figure(res, figs, listing)
        if not listing:
            sys.exit(f"make_figures.py: no scattering.csv in {res}")
        print(f"wrote {figs}/fig_scattering.pdf")
        return
    load_catalogue(res)
    sweep_figures(res, figs, listing)
    timing_figure(res, figs, listing)
    appendix_figure(res, figs, listing)
    work_precision_figures(res, figs, listing)
    by_tol_figure(res, figs, listing)
    far_field_figure(res, figs, listing)
    map_figure(res, figs, listing)
    scattering_figure(res, figs, listing)
    l_cost_figure(res, figs, listing)
    long_time_figure(res, figs, listing)
    with open(os.path.join(figs, "lost.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["what", "why"])
        w.writerows(LOST)
    with open(os.path.join(figs, "figures.md"), "w") as f:
        f.write("| file | what it shows |\n|---|---|\n")
        for name, what in listing:
            f.write(f"| {name} | {what} |\n")
    print(f"wrote {len(listing)} figures to {figs}")


if __name__ == "__main__":
    main()
