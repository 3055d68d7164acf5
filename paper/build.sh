#!/usr/bin/env bash
# bodypoint research appendix: regenerates every CSV from the drivers and every figure from the CSVs.
#
#   paper/build.sh            full studies (thesis grids; the timing recipe, 500 values of n x 22 methods
#                             x 4 runs, dominates) into paper/results/
#   paper/build.sh --quick    the same recipes on coarse grids (63 s on 2 cores) into paper/results-quick/
#
# Outputs: <results>/*.csv (bodypoint study, bodypoint work-precision and its --by-tol view),
# <results>/figures/*.png and
# <results>/figures/figures.md. Every number in the appendix comes from these files.
set -euo pipefail
cd "$(dirname "$0")/.."
quick=""
results=paper/results
if [ "${1:-}" = "--quick" ]; then
  quick="--quick"
  results=paper/results-quick
fi
scripts/setup.sh >/dev/null
bin=build/bin/bodypoint
mkdir -p "$results"
$bin study $quick --results "$results"
$bin work-precision $quick --out "$results/work_precision.csv" --summary "$results/work_precision_summary.md" \
  > "$results/work_precision_summary.txt"
by_tol=()  # auto and every step-size-controlled peer at the same requested tolerance
[ -n "$quick" ] && by_tol=(--scenes close,thesis --tols 1e-4,1e-7,1e-10 --repeats 1)
$bin work-precision --by-tol "${by_tol[@]}" --out "$results/by_tol.csv" --summary "$results/by_tol_summary.md" \
  > "$results/by_tol_summary.txt"
"${PYTHON:-/usr/bin/python3}" paper/make_figures.py "$results" "$results/figures"  # Debian python3-matplotlib
echo "appendix rebuilt in $results"
