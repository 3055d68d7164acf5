"""Section 'Long-time behaviour': invariants and phase error over many periods."""

import os

from macros.common import count, finite, num, power_of_ten, read_csv, sci, slope, tt


# The long-time study's rows from this many periods on are fitted for a growth exponent (earlier ones
# hold the first orbits' transient); an energy error below ROUNDING_LEVEL at the end is the rounding's.
LONG_FIT_FROM = 100.0


ROUNDING_LEVEL = 1e-10


SPLITTINGS = ("lp-y4", "ttl-y4", "kep-y4")


# Brouwer's walk makes the energy's round-off grow like t^(1/2); a fitted exponent above this over a decade
# is read as a drift (a linear one fits 1.0; the reference lp-kl8's walk fits 0.44-0.56 per decade).
BROUWER_ENERGY_EXP_MAX = 0.75


# The walk's phase error, the time integral of a walking energy, grows like t^(3/2), a drift's like t^2: a
# fitted exponent above the midpoint is not called Brouwer's law (one walk's exponent over a decade scatters:
# kep-y4 on the quick build's ellipse fitted 2.16 while its energy fitted 0.53).
BROUWER_PHASE_EXP_MAX = 1.75


UNIT_ROUNDOFF = 2.0 ** -53  # half an ulp of 1 in double precision


DAGGER = "^\\dagger"  # a scene the method diverged on


LONG_SCENES = ("kepler", "two-centres", "spinning")  # the table's order of the energy columns


SCENE_WORDS = {"kepler": "the ellipse", "spinning": "the spinning body's ellipse", "two-centres": "the two-centre orbit"}


def long_time_series(rows):
    """The long-time study's (series, last, exponent) readers over its rows that ended ok."""
    ok = [r for r in rows if r["outcome"] == "ok"]

    def series(scene, m, column):
        rs = [r for r in ok if r["scene"] == scene and r["method"] == m and num(r[column]) > 0]
        return [num(r["periods"]) for r in rs], [num(r[column]) for r in rs]

    def last(scene, m, column):
        _, ys = series(scene, m, column)
        return ys[-1] if ys else float("nan")

    def exponent(scene, m, column):
        xs, ys = series(scene, m, column)
        fit = [(x, y) for x, y in zip(xs, ys) if x >= LONG_FIT_FROM]
        return slope([x for x, _ in fit], [y for _, y in fit]) if len(fit) >= 3 else float("nan")

    return last, exponent


def exponent_text(e):
    """A fitted growth exponent as the table and the text print it: two decimals (1.00, 1.99), or two
    significant digits below 0.1, where two decimals would read 0.00 for a bounded error."""
    return f"{e:.2f}" if abs(e) >= 0.1 else sci(e, 2)


def exponent_range(values):
    """"1.00" when the exponents agree to two decimals, else "1.99 to 2.12"."""
    low, high = exponent_text(min(values)), exponent_text(max(values))
    return low if low == high else f"{low} to {high}"


def long_time_table(rows, out, methods):
    """tab_long_time: per method its step, largest energy error per scene, the energy's growth exponent
    where its error is the method's (not the rounding's), |K2|^2, the ellipse's phase error and exponent.
    Returns {method: (energy exponents per scene, |K2|^2, phase exponent)}."""
    last, exponent = long_time_series(rows)
    found = {}
    with open(os.path.join(out, "tab_long_time.tex"), "w") as f:
        for m in methods:
            first = next(r for r in rows if r["method"] == m)
            # Every method runs at the same step per period (the first scene's period is 2 pi) or tolerance.
            if first["step_name"] == "tol":
                step = f"tol {power_of_ten(num(first['step']))}"
            else:
                step = f"{first['step_name']} $= P/{round(period_of(first) / num(first['step']))}$"
            # A scene the method stopped early on reads its value at the last time it reached (its flagged
            # row, the one the text quotes), marked.
            ended = {r["scene"]: num(r["max_rel_dE"]) for r in rows if r["method"] == m and r["outcome"] != "ok"}
            energy = [f"${sci(ended[sc])}{DAGGER}$" if sc in ended else f"${sci(last(sc, m, 'max_rel_dE'))}$"
                      for sc in LONG_SCENES]
            exps = [exponent(sc, m, "max_rel_dE") for sc in LONG_SCENES]
            above = [e for sc, e in zip(LONG_SCENES, exps) if last(sc, m, "max_rel_dE") > ROUNDING_LEVEL]
            k2 = max(finite(last(sc, m, "rel_dK2sq") for sc in ("spinning", "two-centres")))
            k2q = max(finite(last(sc, m, "abs_dK2Q") for sc in ("kepler", "spinning")))
            phase = exponent("kepler", m, "phase_err")
            cells = [tt(m), step] + energy + [f"${exponent_text(max(finite(above)))}$", f"${sci(k2)}$", f"${sci(k2q)}$",
                                              f"${sci(last('kepler', m, 'phase_err'))}$", f"${exponent_text(phase)}$"]
            f.write(" & ".join(cells) + " \\\\\n")
            found[m] = (exps, k2, phase)
    return found


def long_time(res, out, M):
    """bodypoint study --name long-time: tab_long_time and the ranges the text quotes."""
    rows, _ = read_csv(os.path.join(res, "long_time.csv"))
    last, exponent = long_time_series(rows)
    methods = [m for m in dict.fromkeys(r["method"] for r in rows) if m != "lp-kl8"]
    periods = max(num(r["periods"]) for r in rows)
    M.add("LongPeriods", power_of_ten(periods).strip("$"))
    M.add("LongFitFrom", sci(LONG_FIT_FROM))
    first = next(r for r in rows if r["scene"] == "kepler" and r["method"] == "lp-y4")  # its period is 2 pi
    M.add("LongStepsPerPeriod", count(round(period_of(first) / num(first["step"]))))
    ref = next(r for r in rows if r["scene"] == "kepler" and r["method"] == "lp-kl8")
    M.add("LongRefStepsPerPeriod", count(round(period_of(ref) / num(ref["step"]))))
    found = long_time_table(rows, out, methods)
    M.add("LongDivergedText", ended_text(rows, periods), math_mode=False)
    split_above = [e for m in SPLITTINGS for sc, e in zip(LONG_SCENES, found[m][0])
                   if last(sc, m, "max_rel_dE") > ROUNDING_LEVEL]
    peers = [m for m in methods if m not in SPLITTINGS]
    M.add("LongSplitEnergyExpMax", exponent_text(max(split_above)))
    M.add("LongPeerEnergyExpMin", exponent_text(min(e for m in peers for e in found[m][0])))
    M.add("LongSplitKTwoMax", sci(max(found[m][1] for m in SPLITTINGS)))
    M.add("LongPeerKTwoMin", sci(min(found[m][1] for m in peers)))
    leapfrogs, rk = [found[m][2] for m in ("lp-y4", "ttl-y4")], [found[m][2] for m in peers if m != "rk4"]
    M.add("LongSplitPhaseExp", exponent_range(leapfrogs), math_mode=False)
    M.add("LongPeerPhaseExp", exponent_range(rk), math_mode=False)
    for m, word in (("lp-kl8", "Ref"), ("kep-y4", "Kep")):
        M.add(f"Long{word}EnergyExp", f"{exponent('kepler', m, 'max_rel_dE'):.2f}")
        M.add(f"Long{word}PhaseExp", f"{exponent('kepler', m, 'phase_err'):.2f}")
        M.add(f"Long{word}PhaseEnd", sci(last("kepler", m, "phase_err")))
    M.add("LongKepEnergyEnd", sci(last("kepler", "kep-y4", "max_rel_dE")))
    M.add("LongTtlKeplerEnergyEnd", sci(last("kepler", "ttl-y4", "max_rel_dE")))
    M.add("LongKepVerdict", kepler_split_verdict(rows, periods), math_mode=False)


# What stopped a run early, in the text's words (the study's outcome column; docs/physics.md, "Resolution and
# accuracy flags"): a run flagged diverged left its orbit; a peer whose solver failed stopped with an error.
ENDED_WORDS = {"diverged": "diverges", "failed": "stops, its solver failing,"}


def ended_text(rows, periods):
    """Which methods stopped early, on which orbit, when and how far its energy had gone: the rows whose
    outcome is not ok (one per method and scene, its last), one clause per method and outcome."""
    ended = {}
    for r in rows:
        if r["outcome"] != "ok" and r["method"] != "lp-kl8":
            ended.setdefault((r["method"], r["outcome"]), []).append(
                f"on {SCENE_WORDS[r['scene']]} after ${sci(num(r['periods']))}$ periods "
                f"(energy error ${sci(num(r['max_rel_dE']))}$)")
    if not ended:
        return f"no method leaves its orbit within {power_of_ten(periods)} periods"
    parts = []
    for (m, outcome), where in ended.items():
        places = where[0] if len(where) == 1 else ", ".join(where[:-1]) + " and " + where[-1]
        parts.append(f"{tt(m)} {ENDED_WORDS.get(outcome, f'stops ({outcome})')} {places}")
    return "; ".join(parts) + " (daggers in the table)"


def kepler_split_verdict(rows, periods):
    """What kep-y4's round-off on the ellipse follows: Brouwer's walk, or a drift in the run's last decade
    (a bias per step that the walk hides over shorter spans: seen from 10^5 to 10^6 periods)."""
    xs, es = long_time_series_of(rows, "kep-y4", "max_rel_dE")
    _, ps = long_time_series_of(rows, "kep-y4", "phase_err")
    decade = [i for i, x in enumerate(xs) if x >= periods / 10.0]
    if len(decade) < 3:
        return ", Brouwer's law as well"
    e_last = slope([xs[i] for i in decade], [es[i] for i in decade])
    p_last = slope([xs[i] for i in decade], [ps[i] for i in decade])
    if e_last <= BROUWER_ENERGY_EXP_MAX and p_last <= BROUWER_PHASE_EXP_MAX:
        return ", Brouwer's law as well"
    if e_last <= BROUWER_ENERGY_EXP_MAX:
        return (f"; over the last decade, from {power_of_ten(periods / 10.0)} periods on, its energy walks "
                f"(exponent {e_last:.2f}) while its phase error fits {p_last:.2f}, above the walk's 3/2: one "
                "walk's phase over one decade, not yet Brouwer's law shown")
    first = next(r for r in rows if r["scene"] == "kepler" and r["method"] == "kep-y4")
    steps = (xs[decade[-1]] - xs[decade[0]]) * period_of(first) / num(first["step"])
    bias = (es[decade[-1]] - es[decade[0]]) / steps
    return (f"; over the last decade, from {power_of_ten(periods / 10.0)} periods on, the exponents are "
            f"{e_last:.2f} and {p_last:.2f}: a bias of ${sci(bias)}$ per step in the relative energy, "
            f"${sci(bias / UNIT_ROUNDOFF)}$ times the unit roundoff, that the walk hides over shorter spans")


def period_of(row):
    """The orbit's period of a row, from its time and its number of periods."""
    return num(row["t"]) / num(row["periods"])


def long_time_series_of(rows, method, column):
    """The ellipse's (periods, value) for one method over its rows that ended ok."""
    rs = [r for r in rows if r["scene"] == "kepler" and r["method"] == method and r["outcome"] == "ok"
          and num(r[column]) > 0]
    return [num(r["periods"]) for r in rs], [num(r[column]) for r in rs]
