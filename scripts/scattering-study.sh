#!/usr/bin/env bash
# bodypoint: the scattering study in one command: `bodypoint study --name scattering` (theta(b) for
# b = 1e-3 .. 1e3: a material point against Rutherford's formula, B = 0.2 .. 0.9 and three spin
# orientations; cross-sections, rainbows, r_min, time delay) and its figure, fig_scattering.pdf
# (paper/make_figures.py, the paper's own drawing), into one directory.
# usage: scripts/scattering-study.sh [--quick] [--build DIR] [OUT_DIR]   (default OUT_DIR: results/scattering)
set -euo pipefail
cd "$(dirname "$0")/.."
build=build
out=results/scattering
quick=()
while (($#)); do
  case "$1" in
    --quick) quick=(--quick) ;;
    --build) build="$2"; shift ;;
    -*) echo "usage: scripts/scattering-study.sh [--quick] [--build DIR] [OUT_DIR]" >&2; exit 2 ;;
    *) out="$1" ;;
  esac
  shift
done
mkdir -p "$out"
"$build/bin/bodypoint" study "${quick[@]}" --name scattering --results "$out"
"${PYTHON:-/usr/bin/python3}" paper/make_figures.py --only scattering "$out" "$out"
echo "scripts/scattering-study.sh: $out/scattering.csv, $out/scattering_summary.csv, $out/fig_scattering.pdf"
