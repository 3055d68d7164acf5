"""Section 'Scattering of a spinning body': observables at their limit and the L study's cost."""

import os

from macros.common import camel, count, num, read_csv, sci, tt


def scattering(res, M):
    """bodypoint study --name scattering: Rutherford's agreement, the band of the spinning body's deflection
    over the helix's arrival phase, the rainbows located per phase, the beam's cross-section errors."""
    path = os.path.join(res, "scattering_summary.csv")
    if not os.path.exists(path):
        return
    summary, _ = read_csv(path)
    rows, _ = read_csv(os.path.join(res, "scattering.csv"))
    xs, _ = read_csv(os.path.join(res, "scattering_cross_section.csv"))
    by = {r["series"]: r for r in summary}
    M.add("ScatPoints", count(int(by["B=0"]["points"])))
    M.add("ScatPhases", count(int(by["B=0.7"]["phases"])))
    M.add("ScatRuns", count(len(rows)))
    M.add("ScatSeries", count(len(summary)))
    bs = [num(r["b"]) for r in rows if r["series"] == "B=0"]
    M.add("ScatBMin", sci(min(bs)))
    M.add("ScatBMax", sci(max(bs)))
    M.add("ScatRutherfordAuto", sci(num(by["B=0"]["max_rel_diff_rutherford"])))
    M.add("ScatRutherfordLpKlEight", sci(num(by["B=0 lp-kl8"]["max_rel_diff_rutherford"])))
    M.add("ScatAutoMethods", ", ".join(tt(m) for m in sorted({r["method"] for r in rows if r["series"] == "B=0"})),
          math_mode=False)
    M.add("ScatThetaMaterial", sci(num(by["B=0"]["theta_min_at_smallest_b"]), 3))
    middles = [0.5 * (num(by["B=" + B]["theta_min_at_smallest_b"]) + num(by["B=" + B]["theta_max_at_smallest_b"]))
               for B in ("0.2", "0.5", "0.7", "0.9")]
    falls = all(a > b for a, b in zip(middles, middles[1:]))
    M.add("ScatTrend", "falls as its coupling grows" if falls else "depends on its coupling", math_mode=False)
    for B in ("0.2", "0.5", "0.7", "0.9"):
        r = by["B=" + B]
        word = camel("B" + B.replace("0.", ""))
        lo, hi = num(r["theta_min_at_smallest_b"]), num(r["theta_max_at_smallest_b"])
        # The deflection at the smallest b and how far the arrival phase moves it (the band's width
        # over its middle, in per cent).
        M.add(f"ScatTheta{word}", sci(0.5 * (lo + hi), 3))
        M.add(f"ScatBand{word}", f"{100.0 * (hi - lo) / (0.5 * (lo + hi)):.2g}")
        M.add(f"ScatRainbows{word}", count(int(r["rainbows"])))
        M.add(f"ScatRainbowLo{word}", sci(num(r["rainbow_theta_min"]), 3))
        M.add(f"ScatRainbowHi{word}", sci(num(r["rainbow_theta_max"]), 3))
        M.add(f"ScatOutOfPlane{word}", sci(num(r["max_abs_out_of_plane"]), 2))
        M.add(f"ScatRMin{word}", sci(num(r["min_r_min"]), 2))
        M.add(f"ScatAsymptote{word}", sci(num(r["max_asymptote_error"]), 1))
        M.add(f"ScatStartDistance{word}", sci(num(r["max_start_distance_error"]), 1))
    along, across = by["B=0.7 spin along K1"], by["B=0.7 spin across K1"]
    M.add("ScatAlongFailed", count(int(along["failed"])))
    M.add("ScatThetaAlong", sci(num(along["theta_min_at_smallest_b"]), 4))
    M.add("ScatThetaAcross", sci(num(across["theta_max_at_smallest_b"]), 2))
    covered = [r for r in xs if r["covered"] == "1" and num(r["dsigma_domega"]) > 0]
    rel = [num(r["quadrature_error"]) / num(r["dsigma_domega"]) for r in covered]
    M.add("ScatXsBins", count(len(covered)))
    M.add("ScatXsErrMedian", sci(sorted(rel)[len(rel) // 2], 2))
    zero = [r for r in covered if r["series"] == "B=0"]
    M.add("ScatXsRutherfordMax", sci(max(abs(num(r["dsigma_domega"]) / num(r["dsigma_rutherford_gc"]) - 1) for r in zero), 2))
    delays = [num(r["time_delay"]) for r in rows if r["series"] == "B=0.7" and r["failure"] == ""]
    delays0 = [num(r["time_delay"]) for r in rows if r["series"] == "B=0" and r["failure"] == ""]
    M.add("ScatDelaySevenMin", sci(min(delays), 2))
    M.add("ScatDelaySevenMax", sci(max(delays), 2))
    M.add("ScatDelayZeroMin", sci(min(delays0), 2))
    M.add("ScatDelayZeroMax", sci(max(delays0), 2))


def l_cost(res, M):
    """bodypoint study --name L (L_cost.csv): an encounter's whole cost against its start distance, with and
    without far legs, beside the thesis's fixed step's; how far apart its deflections at the limit are."""
    path = os.path.join(res, "L_cost.csv")
    if not os.path.exists(path):
        return
    rows, _ = read_csv(path)
    ok = [r for r in rows if r["failure"] == ""]
    legs = [r for r in ok if r["far_legs"] == "1"]
    last = max(ok, key=lambda r: num(r["L"]))
    M.add("LCostLMin", count(round(min(num(r["L"]) for r in ok))))
    M.add("LCostLMax", sci(num(last["L"])))
    M.add("LCostAtMax", count(int(last["force_evals"])))
    M.add("LCostFixedAtMax", sci(num(last["fixed_step_evals"])))
    without = [r for r in ok if r["far_legs"] == "0"]
    top = max(without, key=lambda r: num(r["L"]))
    M.add("LCostNoLegsL", count(round(num(top["L"]))))
    M.add("LCostNoLegs", count(int(top["force_evals"])))
    if legs:
        M.add("LCostLegsFrom", count(round(min(num(r["L"]) for r in legs))))
        M.add("LCostLegsSpread", f"{max(num(r['force_evals']) for r in legs) / min(num(r['force_evals']) for r in legs):.2f}")
    thetas = [num(r["deflection"]) for r in ok]
    M.add("LCostThetaSpread", sci(max(thetas) - min(thetas), 1))
    M.add("LCostErrMax", sci(max(num(r["deflection_error"]) for r in ok), 1))
