#!/usr/bin/env bash
# bodypoint research appendix: regenerates every CSV from the drivers, every figure and every number
# of the paper from the CSVs, and compiles paper/build/bodypoint.pdf.
#
#   paper/build.sh            thesis grids, every named scene, into paper/results/
#   paper/build.sh --quick    the same recipes, scenes and sections on coarse grids into paper/results-quick/
#
# Steps: bodypoint study (d, L, h, Kx sweeps, timing, force evaluations, appendix 1, errata, the sweeps
# as published, stress, the (d, L) map, scattering), bodypoint work-precision (ladders and --by-tol),
# bench/far_field.py (where the steps go, the far field's resonances), gsl_peer (GSL as bodypoint
# drives it against a plain C program), bench_steps (cost per step), bench_batch (sweep
# throughput per core),
# make_figures.py (vector PDF), make_macros.py (LaTeX macros and tables), latexmk.
# Every time is taken under the commands' timing rules (experiments/stopwatch.hpp; Google Benchmark:
# 5 repetitions, randomly interleaved, medians): run it on a machine doing nothing else. A time that
# does not count (contended, spread) is flagged in its CSV and the paper prints no flagged time.
# BODYPOINT_NO_SETUP=1 skips scripts/setup.sh and BODYPOINT_BUILD_DIR names the build tree (default
# build/); the ctest that builds the quick paper sets both.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=full
results=paper/results
if [ "${1:-}" = "--quick" ]; then
  mode=quick
  results=paper/results-quick
elif [ -n "${1:-}" ]; then
  echo "usage: paper/build.sh [--quick]" >&2
  exit 2
fi
[ "${BODYPOINT_NO_SETUP:-0}" = 1 ] || scripts/setup.sh >/dev/null
bindir="${BODYPOINT_BUILD_DIR:-build}/bin"
bin=$bindir/bodypoint
py="${PYTHON:-/usr/bin/python3}"  # Debian's python3 with python3-matplotlib
start=$(date +%s)
mkdir -p "$results"

# The machine and the software every timing of this build ran on (paper: "Reproducing this document").
builddir="${BODYPOINT_BUILD_DIR:-build}"
cache_value() { sed -n "s/^$1:[A-Z]*=//p" "$builddir/CMakeCache.txt" | head -1; }
header_value() { sed -n "s/^#define $2 *\(.*\)$/\1/p" "$1" 2>/dev/null | head -1; }
cxx=$(cache_value CMAKE_CXX_COMPILER)
eigen=/usr/include/eigen3/Eigen/src/Core/util/Macros.h
{
  echo "cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)"
  echo "mhz=$(sed -n 's/^cpu MHz[[:space:]]*: //p' /proc/cpuinfo | head -1)"
  echo "cores=$(nproc)"
  # "hypervisor" among the CPU's flags: a virtual machine (its host may slow a core down unseen).
  if grep -qw hypervisor /proc/cpuinfo; then echo "virtual=yes"; else echo "virtual=no"; fi
  echo "load=$(cut -d' ' -f1-3 /proc/loadavg)"
  echo "compiler=$("$cxx" --version | head -1)"
  echo "flags=$(cache_value CMAKE_CXX_FLAGS) $(cache_value CMAKE_CXX_FLAGS_RELEASE) ($(cache_value CMAKE_BUILD_TYPE))"
  echo "boost=$(header_value /usr/include/boost/version.hpp BOOST_LIB_VERSION | tr -d '"' | tr _ .)"
  echo "eigen=$(header_value $eigen EIGEN_WORLD_VERSION).$(header_value $eigen EIGEN_MAJOR_VERSION).$(header_value $eigen EIGEN_MINOR_VERSION)"
  echo "gsl=$(gsl-config --version 2>/dev/null || echo none)"
  echo "kernel=$(uname -sr)"
} > "$results/platform.txt"

# Where the time goes: each step's wall seconds, in order, into build_stages.txt; the last step's in
# stage_seconds.
: > "$results/build_stages.txt"
stage_start=$(date +%s.%N)
stage() {
  local now
  now=$(date +%s.%N)
  stage_seconds=$(awk -v a="$now" -v b="$stage_start" 'BEGIN { print a - b }')
  echo "$1 $stage_seconds" >> "$results/build_stages.txt"
  stage_start=$now
}

q=()
[ $mode = quick ] && q=(--quick)
# --resume: an interrupted build continues its sweeps from their journals (rows of this same build).
$bin study "${q[@]}" --resume --results "$results"
stage study
$bin study "${q[@]}" --name stress --results "$results"
stage stress
$bin study "${q[@]}" --name scattering --results "$results"
stage scattering
# The (d, L) stability map (thesis resolution in the full build), timed: its wall time is a number of
# the paper.
$bin study "${q[@]}" --resume --name dL-map --results "$results"
stage dL-map
echo "$stage_seconds $(nproc)" > "$results/dL_map_seconds.txt"

# Google Benchmark under the same rules: 5 repetitions in random interleaving, medians (and their
# coefficient of variation) only.
bench=(--benchmark_repetitions=5 --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true)
if [ $mode = quick ]; then
  wp=(--quick --scenes all --max-evals 3e5)
  by_tol=(--tols 1e-4,1e-7,1e-10 --scenes thesis,close,material,two-centres)
  bench+=(--benchmark_min_time=0.01)
else
  wp=()
  by_tol=()
fi
$bin work-precision "${wp[@]}" --out "$results/work_precision.csv" --summary "$results/work_precision_summary.md" \
  > "$results/work_precision_summary.txt"
stage work-precision
$bin work-precision --by-tol "${by_tol[@]}" --out "$results/by_tol.csv" --summary "$results/by_tol_summary.md" \
  > "$results/by_tol_summary.txt"
stage by-tol
# The accuracy mode's honesty on 256 scenes it was not tuned on, at three tolerances (768 runs, about
# 20 s), against long-double references (no timing, two processes at a time).
"$py" bench/estimate_grid.py "$bin" --out "$results/estimate_grid.csv" > "$results/estimate_grid.txt"
stage estimate-grid
# Where a spinning body's steps go on the close scene (auto and the peers), and the far field's
# resonances against the spin angle per step (the Python module, from the build tree).
PYTHONPATH="${BODYPOINT_BUILD_DIR:-build}/python" "$py" bench/far_field.py "$bin" --out-dir "$results" \
  > "$results/far_field.md"
stage far-field
# GSL as bodypoint drives it against GSL with a plain C right-hand side and its driver, in one process
# (bench/gsl_peer.cpp; the paper prints the ratios per force evaluation, also when one exceeds the
# 10 % bound).
if [ -x "$bindir/gsl_peer" ]; then
  "$bindir/gsl_peer" --csv "$results/gsl_peer.csv" > "$results/gsl_peer.md" ||
    echo "paper/build.sh: GSL's peer above the plain C program's cost by more than 10 % (results/gsl_peer.md; the paper says so)" >&2
fi
stage gsl-peer
# Google Benchmark's medians keep their names; the coefficient of variation rows (_cv) are the spread.
bench_medians() {
  grep -v '^"BM_[A-Za-z]*/.*_\(mean\|stddev\)"' "$1" | sed 's#_median"#"#' > "$1.2" && mv "$1.2" "$1"
}
# Cost per step of every method on the thesis scene.
"$bindir/bench_steps" --benchmark_filter='BM_Step/.*/thesis' "${bench[@]}" --benchmark_format=csv \
  > "$results/bench_steps.csv.tmp" 2>/dev/null
bench_medians "$results/bench_steps.csv.tmp"
mv "$results/bench_steps.csv.tmp" "$results/bench_steps.csv"
stage bench-steps
# Sweep throughput per core: the scalar loop against batches of vector lanes.
"$bindir/bench_batch" "${bench[@]}" --benchmark_format=csv > "$results/bench_batch.csv.tmp" 2>/dev/null
bench_medians "$results/bench_batch.csv.tmp"
mv "$results/bench_batch.csv.tmp" "$results/bench_batch.csv"
stage bench-batch
# One sweep run scalar, in lanes, on 2 threads, 2 MPI ranks and 2 shards: throughput and efficiency.
scale=()
[ $mode = quick ] && scale=(--quick)
scripts/ensemble-scaling.sh "${scale[@]}" --build "${BODYPOINT_BUILD_DIR:-build}" --csv "$results/scaling.csv" \
  > "$results/scaling.md"
stage scaling

# The catalogue: the scripts group methods by the families it gives (paper/catalogue.py).
"$bin" methods --csv > "$results/methods.csv.tmp"
mv "$results/methods.csv.tmp" "$results/methods.csv"

# How long the results took (the paper states it beside its grids).
echo "$(( $(date +%s) - start ))" > "$results/build_seconds.txt"

out=paper/build
mkdir -p "$out"
"$py" paper/make_figures.py "$results" "$out/figures"
"$py" paper/make_macros.py "$results" "$out/generated" "$mode"
cp paper/bodypoint.tex paper/bodypoint.bib "$out/"
(cd "$out" && latexmk -pdf -interaction=nonstopmode -halt-on-error bodypoint.tex > latexmk.out 2>&1) || {
  tail -40 "$out/latexmk.out" >&2
  echo "paper/build.sh: LaTeX failed; the log is $out/bodypoint.log" >&2
  exit 1
}
echo "paper/build.sh: $out/bodypoint.pdf ($mode, $(( $(date +%s) - start )) s; results in $results)"
