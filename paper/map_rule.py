"""Which panels of the (d, L) map are worth a picture (issue #83: 31 near-uniform panels, "a table would do").

A method's map is uniform when every run ended ok and its log10 max relative energy deviation spans at most
UNIFORM_DECADES over the map, or when no run ended ok (an all-black panel): its row of tab_map says all there
is to say (make_macros.py), and only the other methods get a panel of fig_dL_map (make_figures.py).
"""
import math

# Two decades: the spread the rounding alone makes over the map for the splittings at h = 1e-4 (their
# deviations lie between 1e-15 and 1e-13).
UNIFORM_DECADES = 2.0


def log_deviations(rows):
    """log10 max_rel_dE of the runs that ended ok with a deviation above zero."""
    out = []
    for r in rows:
        try:
            v = float(r["max_rel_dE"])
        except (TypeError, ValueError):
            continue
        if r["outcome"] == "ok" and v > 0:
            out.append(math.log10(v))
    return out


def uniform(rows):
    """A method's map (its rows of dL_map.csv) is uniform: every run ok with deviations within UNIFORM_DECADES,
    or no run ok."""
    if not any(r["outcome"] == "ok" for r in rows):
        return True
    logs = log_deviations(rows)
    return all(r["outcome"] == "ok" for r in rows) and bool(logs) and max(logs) - min(logs) <= UNIFORM_DECADES
