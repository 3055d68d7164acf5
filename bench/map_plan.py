"""What a map of auto rows costs with its plan, against each row searched alone and the per-row cheapest run.

Runs `bodypoint sweep --methods auto --accuracy TOL` on a few maps of the thesis's scene, and the same grid with
named methods (each row searched alone: the cheapest delivered run per row is the best any single method did
there). Prints, per map: the whole map's force evaluations (every search's runs: pilots, companions, misses),
the sum of the rows' delivered runs, the per-row cheapest delivered run summed (an encounter's own run; the
whole counts its run from twice the start distance too), their ratio, the estimates'
median and maximum against TOL, and how many rows were planned and held on their first pair. With --check,
every auto row is run again by `simulate --method CHOSEN --h H_CHOSEN --omega-c OMEGA_C --reference` and its
estimate compared with the error against Boost.Odeint's long-double reference.
With --before BINARY the same maps are run by that build too (say, one before the plan).

    /usr/bin/python3 bench/map_plan.py build/bin/bodypoint [--before OLD] [--check] [--quick]
"""
import argparse
import csv
import io
import json
import statistics
import subprocess

# (name, grid arguments, TOL, end time; None: each encounter to its departure): maps over the scene's geometry,
# its coupling, an attracting centre, a tight tolerance, and encounters (whose rows also run from twice their
# start distance, column start_distance_force_evals, counted in the whole).
MAPS = [
    ("d x L", ["--grid", "d=5:15:5", "--grid", "L=100:400:100"], 1e-8, 60),
    ("d x B", ["--grid", "d=2:40:2", "--grid", "B=0.3:0.9:0.1"], 1e-8, 60),
    ("A x d", ["--grid", "A=1:3:1", "--grid", "d=3:12:3"], 1e-6, 40),
    ("K1 x Kz", ["--grid", "K1=3:7:1", "--grid", "Kz=1:5:2"], 1e-10, 60),
    ("encounters b x arrival phase", ["--scattering", "--grid", "b=1:4:1", "--grid", "arrival_phase=0:3:1"], 1e-8, None),
    # Far passes, whose cost is the far field's spin-limited steps at any step (the 10^4-point map of
    # bench/map_at_scale.py has most of its rows there).
    ("far passes d x B", ["--grid", "d=40:100:20", "--grid", "B=0.2:0.9:0.1"], 1e-9, 50),
]
QUICK = [MAPS[0], MAPS[2]]
NAMED = "logh-verlet,logh-y4,logh-pefrl,logh-bm4,logh-kl6,logh-kl8,lp-y4,lp-kl6"
# A planned row that held costs its run and its companion at twice the step: 1.5 runs.
FIRST_PAIR = 1.5
FIRST_PAIR_SLACK = 0.05


def sweep(binary, grid, tol, t_end, methods):
    end = ["--t-end", str(t_end)] if t_end else []
    out = subprocess.run([binary, "sweep", *grid, "--methods", methods, "--accuracy", str(tol), *end, "--threads", "2"],
                         capture_output=True, text=True, check=True).stdout
    return list(csv.DictReader(io.StringIO("".join(l for l in out.splitlines(True) if not l.startswith("#")))))


def axes_of(rows):
    keys = list(rows[0])
    return keys[:keys.index("method")]


def cheapest(named, tol):
    """The per-row cheapest delivered run of the named methods that delivered TOL there."""
    axes, best = axes_of(named), {}
    for r in named:
        if r["outcome"] == "ok" and float(r["err_estimate"]) <= tol:
            key = tuple(r[a] for a in axes)
            best[key] = min(best.get(key, float("inf")), int(r["force_evals"]))
    return sum(best.values())


def cost(r):
    """A row's every force evaluation: its search, an encounter's run from twice its start distance and its events
    (a build before the events' column counted them nowhere)."""
    return sum(int(r.get(k) or 0) for k in ("search_force_evals", "start_distance_force_evals", "event_force_evals"))


def summary(rows, tol, cheapest_sum):
    whole = sum(cost(r) for r in rows)
    ests = [float(r["err_estimate"]) for r in rows]
    held = sum("planned from" in r["err_basis"] and
               abs(int(r["search_force_evals"]) / int(r["force_evals"]) - FIRST_PAIR) < FIRST_PAIR_SLACK for r in rows)
    planned = sum("planned from" in r["err_basis"] for r in rows)
    return (f"whole {whole:>9,} delivered {sum(int(r['force_evals']) for r in rows):>9,} "
            f"whole/cheapest {whole / cheapest_sum:5.2f}  estimate/TOL median {statistics.median(ests) / tol:.3f} "
            f"max {max(ests) / tol:.3f}  planned {planned}, held {held} of {len(rows)}")


def check(binary, rows, t_end):
    """Each row's estimate over its error against the long-double reference."""
    axes, ratios = axes_of(rows), []
    for r in rows:
        cmd = [binary, "simulate", "--method", r["chosen"], "--h", r["h_chosen"], "--t-end", str(t_end), "--reference",
               "--json", "--no-error-estimate"]
        if r["omega_c"] not in ("", "nan"):
            cmd += ["--omega-c", r["omega_c"]]
        for a in axes:
            cmd += ["--" + a, r[a]]
        d = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
        ratios.append(float(r["err_estimate"]) / d["err_rel"])
    return (f"estimate/error min {min(ratios):.2f} median {statistics.median(ratios):.2f} max {max(ratios):.2f}, "
            f"more than 3x low {sum(x < 1 / 3 for x in ratios)} of {len(ratios)}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("binary")
    ap.add_argument("--before", help="another build's bodypoint, run on the same maps")
    ap.add_argument("--check", action="store_true", help="each auto row against the long-double reference")
    ap.add_argument("--quick", action="store_true", help="two small maps")
    args = ap.parse_args()
    for name, grid, tol, t_end in QUICK if args.quick else MAPS:
        base = cheapest(sweep(args.binary, grid, tol, t_end, NAMED), tol)
        print(f"{name} at TOL {tol:g}: per-row cheapest delivered run summed {base:,}")
        for label, binary in [("before", args.before), ("plan", args.binary)]:
            if binary:
                rows = sweep(binary, grid, tol, t_end, "auto")
                print(f"  {label:>6}: {summary(rows, tol, base)}")
        if args.check and t_end:  # an encounter's run ends at its departure, not at a time simulate is given
            print("  " + check(args.binary, sweep(args.binary, grid, tol, t_end, "auto"), t_end))


if __name__ == "__main__":
    main()
