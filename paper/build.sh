#!/usr/bin/env bash
# bodypoint research appendix: regenerates every CSV from the drivers, every figure and every number
# of the paper from the CSVs, and compiles paper/build/bodypoint.pdf.
#
#   paper/build.sh            thesis grids, every named scene, into paper/results/
#   paper/build.sh --quick    the same recipes, scenes and sections on coarse grids into paper/results-quick/
#   paper/build.sh --resume   (with or without --quick) an interrupted build goes on from its first
#                             unfinished step (the full build takes hours: it can be run in sittings)
#   paper/build.sh --park     (with or without --quick) packs an interrupted build's results into
#                             paper/sittings/, to be committed, so that a sitting on another machine (a
#                             fresh clone) resumes it: --resume unpacks them when its results directory is empty
#
# Steps: bodypoint study (d, L, h, Kx sweeps, timing, force evaluations, appendix 1, errata, the sweeps
# as published, stress, the (d, L) map, scattering, long-time), bodypoint work-precision (ladders and --by-tol),
# bench/far_field.py (where the steps go, the far field's resonances), gsl_peer (GSL as bodypoint
# drives it against a plain C program), bench_steps (cost per step), bench_batch (sweep
# throughput per core),
# make_figures.py (vector PDF), make_macros.py (LaTeX macros and tables), latexmk.
# Every time is taken under the commands' timing rules (experiments/cli/stopwatch.hpp; Google Benchmark:
# 5 repetitions, randomly interleaved, medians): run it on a machine doing nothing else. A time that
# does not count (contended, spread) is flagged in its CSV and the paper prints no flagged time.
# BODYPOINT_NO_SETUP=1 skips scripts/setup.sh and BODYPOINT_BUILD_DIR names the build tree (default
# build/); the ctest that builds the quick paper sets both.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=full
resume=0
park=0
for arg in "$@"; do
  case "$arg" in
    --quick) mode=quick ;;
    --resume) resume=1 ;;
    --park) park=1 ;;
    *) echo "usage: paper/build.sh [--quick] [--resume | --park]" >&2; exit 2 ;;
  esac
done
results=paper/results
[ $mode = quick ] && results=paper/results-quick
# An unfinished build parked between sittings (--park), committed so that a fresh clone can go on with it.
parked="paper/sittings/$(basename "$results").tar.xz"
if [ $park = 1 ]; then
  [ $resume = 0 ] || { echo "paper/build.sh: --park and --resume are two separate runs" >&2; exit 2; }
  [ -f "$results/build_state.txt" ] || { echo "paper/build.sh: --park: $results holds no build" >&2; exit 2; }
  exec 9> "$results/.lock"
  flock -n 9 || { echo "paper/build.sh: --park: a build is still running in $results; stop it first" >&2; exit 2; }
  mkdir -p paper/sittings
  tar -C "$(dirname "$results")" --exclude=.lock -cJf "$parked.tmp" "$(basename "$results")"
  mv "$parked.tmp" "$parked"
  echo "paper/build.sh: parked $results (its last logged step: $(tail -1 "$results/build_stages.txt" 2>/dev/null | cut -d' ' -f1)) in $parked ($(du -h "$parked" | cut -f1)); commit it, then paper/build.sh --resume goes on"
  exit 0
fi
if [ $resume = 1 ] && [ ! -f "$results/build_state.txt" ] && [ -f "$parked" ]; then
  mkdir -p "$(dirname "$results")"
  tar -C "$(dirname "$results")" -xJf "$parked"
  echo "paper/build.sh: unpacked the parked build $parked into $results"
fi
[ "${BODYPOINT_NO_SETUP:-0}" = 1 ] || scripts/setup.sh >/dev/null
bindir="${BODYPOINT_BUILD_DIR:-build}/bin"
bin=$bindir/bodypoint
py="${PYTHON:-/usr/bin/python3}"  # Debian's python3 with python3-matplotlib
mkdir -p "$results"
# Held while the build runs, taken before anything in $results is written (a second build started beside a
# running one must not truncate its build_stages.txt or rewrite its build_state.txt before it is refused);
# --park refuses to pack results that are still being written.
exec 9> "$results/.lock"
flock -n 9 || { echo "paper/build.sh: another build is running in $results" >&2; exit 2; }

# --resume: a build interrupted (killed, or its machine needed) goes on from its first unfinished
# step, keeping the finished steps' results, provided they come from the same mode, revision, binary and
# CPU (build_state.txt); each step's time is its own, so the stated build time is the sum of the steps.
stages="$results/build_stages.txt"
state="$results/build_state.txt"
# The revision is the newest commit that changed what makes the results: not the parked sittings, the
# documentation, or the typesetting of the paper (its text, bibliography, figure and macro scripts), which
# the last sitting applies to all the results; so a build parked in one commit resumes in the next.
not_inputs=(':(exclude)paper/sittings' ':(exclude)docs' ':(exclude)*.md' ':(exclude)paper/*.tex'
  ':(exclude)paper/*.bib' ':(exclude)paper/macros' ':(exclude)paper/make_figures.py'
  ':(exclude)paper/make_macros.py' ':(exclude)paper/check_paper.py' ':(exclude)paper/bodypoint.pdf'
  ':(exclude)paper/bodypoint-build.txt')
revision=$(git log -1 --format=%H -- . "${not_inputs[@]}" 2>/dev/null || true)
[ -n "$revision" ] || revision=unknown
[ -z "$(git status --porcelain -- . "${not_inputs[@]}" 2>/dev/null)" ] || revision="$revision+uncommitted"
identity="mode=$mode revision=$revision binary=$(sha256sum "$bin" | cut -c1-16) cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)"
sittings=1
if [ $resume = 1 ]; then
  if [ ! -f "$state" ] || [ ! -f "$stages" ]; then
    echo "paper/build.sh: --resume: $results holds no interrupted build (no build_state.txt); run without --resume" >&2
    exit 2
  fi
  if [ "$(head -1 "$state")" != "$identity" ]; then
    echo "paper/build.sh: --resume: $results was made by another build ($(head -1 "$state")), not by this one ($identity); run without --resume" >&2
    exit 2
  fi
  sittings=$(( $(sed -n 's/^sittings=//p' "$state") + 1 ))
else
  : > "$stages"
fi
{ echo "$identity"; echo "sittings=$sittings"; } > "$state.tmp" && mv "$state.tmp" "$state"

# The machine and the software every timing of this build ran on (paper: "Reproducing this document").
builddir="${BODYPOINT_BUILD_DIR:-build}"
cache_value() { sed -n "s/^$1:[A-Z]*=//p" "$builddir/CMakeCache.txt" | head -1; }
header_value() { sed -n "s/^#define $2 *\(.*\)$/\1/p" "$1" 2>/dev/null | head -1; }
cxx=$(cache_value CMAKE_CXX_COMPILER)
eigen=/usr/include/eigen3/Eigen/src/Core/util/Macros.h
[ $resume = 1 ] || {
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

# Where the time goes: each step's wall seconds, in order, into build_stages.txt.
now() { date +%s.%N; }
since() { awk -v a="$(now)" -v b="$1" 'BEGIN { print a - b }'; }
# step NAME COMMAND...: runs the step unless --resume finds it finished; logs its wall seconds. A step
# stopped by a signal logs the seconds it ran as "NAME(part)" (a journalled step goes on from there when
# resumed), so that the build's time is still the sum of every sitting's steps.
step() {
  local name=$1 t0
  shift
  if [ $resume = 1 ] && grep -q "^$name " "$stages"; then
    echo "paper/build.sh: $name finished in an earlier sitting, kept"
    return
  fi
  t0=$(now)
  trap 'echo "$name(part) $(since "$t0")" >> "$stages"; exit 130' INT TERM
  "$@"
  trap - INT TERM
  echo "$name $(since "$t0")" >> "$stages"
}

q=()
[ $mode = quick ] && q=(--quick)
# --resume: an interrupted build continues its sweeps from their journals (rows of this same build).
step study "$bin" study "${q[@]}" --resume --results "$results"
step stress "$bin" study "${q[@]}" --name stress --results "$results"
step scattering "$bin" study "${q[@]}" --name scattering --results "$results"
# Bound orbits over 10^7 periods (quick: 10^3): some 6 CPU hours, journalled every 10^4 periods, so that an
# interrupted build goes on from where each run stopped (--resume).
long_time=(--periods 1e7)
[ $mode = quick ] && long_time=()
step long-time "$bin" study "${q[@]}" --resume --name long-time "${long_time[@]}" --results "$results"
# The (d, L) stability map (thesis resolution in the full build), timed: its wall time is a number of
# the paper.
# One run (a study of minutes is not repeated), so its time is judged by the share of the cores other
# processes used meanwhile (scripts/contention.sh; paper/timing_rule.py): wall seconds, cores, that share.
source scripts/contention.sh
dL_map() {
  local t0
  t0=$(now)
  contention_start
  "$bin" study "${q[@]}" --resume --name dL-map --results "$results"
  echo "$(since "$t0") $(nproc) $(contention_share)" > "$results/dL_map_seconds.txt"
}
step dL-map dL_map
# A map at an accuracy at scale (issue #80): 10^4 trajectories (quick: 400) of the thesis's scene over (d, B),
# auto at TOL 1e-9 on 2 threads, 5 warm repeats; CPU and wall time and force evaluations per trajectory,
# its estimates, and a sample of rows against long-double references (bench/map_at_scale.py).
map_scale=(--points 100 --sample 24)
[ $mode = quick ] && map_scale=(--points 20 --sample 8)
map_at_scale() {
  "$py" bench/map_at_scale.py "$bin" "${map_scale[@]}" --threads 2 --repeats 5 --csv "$results/map_scale.csv" \
    > "$results/map_scale.txt" ||
    echo "paper/build.sh: the map at scale has an estimate above TOL or a sampled error above it (results/map_scale.txt; the paper says so)" >&2
}
step map-scale map_at_scale

# Google Benchmark under the same rules: 5 repetitions in random interleaving, medians (and their
# coefficient of variation) only.
bench=(--benchmark_repetitions=5 --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true)
if [ $mode = quick ]; then
  wp=(--quick --max-evals 3e5)
  by_tol=(--tols 1e-4,1e-7,1e-10 --scenes thesis,close,material,two-centres)
  bench+=(--benchmark_min_time=0.01)
else
  wp=()
  by_tol=()
fi
# Work-precision one scene at a time (each scene's configurations are timed interleaved; a scene is
# the unit a resumed build keeps), then one CSV and one summary of every scene.
mkdir -p "$results/wp"
wp_scene() {
  "$bin" work-precision "${wp[@]}" --scenes "$1" --out "$results/wp/$1.csv" --summary "$results/wp/$1_summary.md" \
    > /dev/null
}
wp_files=()
for scene in $("$bin" work-precision --list-scenes); do
  step "work-precision:$scene" wp_scene "$scene"
  wp_files+=("$scene")
done
"$py" - "$results" "${wp_files[@]}" <<'PY'
import os, sys
res, scenes = sys.argv[1], sys.argv[2:]
csvs = [open(os.path.join(res, "wp", s + ".csv")).read().splitlines() for s in scenes]
sums = [open(os.path.join(res, "wp", s + "_summary.md")).read().splitlines() for s in scenes]
# The CSV: the first scene's header and notes, every scene's reference line, every scene's rows.
first = csvs[0]
notes = [l for l in first[1:] if l.startswith("#")]
refs = [l for c in csvs for l in c[1:] if l.startswith("# reference ")]
cut = max(i for i, l in enumerate(notes) if l.startswith("# reference "))
head = [first[0]] + [l for l in notes[:cut + 1] if not l.startswith("# reference ")] + refs + notes[cut + 1:]
rows = [l for c in csvs for l in c[1:] if not l.startswith("#")]
# The summary: the first scene's comment and table head, every scene's table rows.
table = sums[0][:3] + [l for s in sums for l in s[3:] if l.startswith("| ")]
for name, lines in [("work_precision.csv", head + rows), ("work_precision_summary.md", table),
                    ("work_precision_summary.txt", table[1:])]:
    path = os.path.join(res, name)
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(path + ".tmp", path)
PY
by_tol_step() {
  "$bin" work-precision --by-tol "${by_tol[@]}" --out "$results/by_tol.csv" --summary "$results/by_tol_summary.md" \
    > "$results/by_tol_summary.txt"
}
step by-tol by_tol_step
# The accuracy mode's honesty on 256 scenes it was not tuned on, at three tolerances (768 runs, about
# 20 s), against long-double references (no timing, two processes at a time).
estimate_grid() { "$py" bench/estimate_grid.py "$bin" --out "$results/estimate_grid.csv" > "$results/estimate_grid.txt"; }
step estimate-grid estimate_grid
# The same on the accuracy mode's other branches (TTL, ks, the Lie-Poisson far field, several centres) and
# far-ip under --tol, at TOL 1e-4 to 1e-12 (288 runs, about 10 s).
estimate_branches() {
  "$py" bench/estimate_grid.py "$bin" --branches --out "$results/estimate_branches.csv" > "$results/estimate_branches.txt"
}
step estimate-branches estimate_branches
# Where a spinning body's steps go on the close scene (auto and the peers), and the far field's
# resonances against the spin angle per step (the Python module, from the build tree).
far_field() {
  PYTHONPATH="${BODYPOINT_BUILD_DIR:-build}/python" "$py" bench/far_field.py "$bin" --out-dir "$results" \
    > "$results/far_field.md"
}
step far-field far_field
# GSL as bodypoint drives it against GSL with a plain C right-hand side and its driver, in one process
# (bench/gsl_peer.cpp; the paper prints the ratios per force evaluation, also when one exceeds the
# 10 % bound).
gsl_peer() {
  if [ -x "$bindir/gsl_peer" ]; then
    "$bindir/gsl_peer" --csv "$results/gsl_peer.csv" > "$results/gsl_peer.md" ||
      echo "paper/build.sh: GSL's peer above the plain C program's cost by more than 10 % (results/gsl_peer.md; the paper says so)" >&2
  fi
}
step gsl-peer gsl_peer
# What a run's error estimate costs: simulate and Python's integrate with and without it, CPU time of 5
# interleaved warm repeats (bench/estimate_cost.py; a few seconds).
estimate_cost() {
  "$py" bench/estimate_cost.py "$bin" --repeats 5 --python "${BODYPOINT_BUILD_DIR:-build}/python" \
    --csv "$results/estimate_cost.csv" > "$results/estimate_cost.md"
}
step estimate-cost estimate_cost
# Google Benchmark's medians keep their names; the coefficient of variation rows (_cv) are the spread.
bench_medians() {
  grep -v '^"BM_[A-Za-z]*/.*_\(mean\|stddev\)"' "$1" | sed 's#_median"#"#' > "$1.2" && mv "$1.2" "$1"
}
# Cost per step of every method on the thesis scene.
bench_steps() {
  "$bindir/bench_steps" --benchmark_filter='BM_Step/.*/thesis' "${bench[@]}" --benchmark_format=csv \
    > "$results/bench_steps.csv.tmp" 2>/dev/null
  bench_medians "$results/bench_steps.csv.tmp"
  mv "$results/bench_steps.csv.tmp" "$results/bench_steps.csv"
}
step bench-steps bench_steps
# Sweep throughput per core: the scalar loop against batches of vector lanes.
bench_batch() {
  "$bindir/bench_batch" "${bench[@]}" --benchmark_format=csv > "$results/bench_batch.csv.tmp" 2>/dev/null
  bench_medians "$results/bench_batch.csv.tmp"
  mv "$results/bench_batch.csv.tmp" "$results/bench_batch.csv"
}
step bench-batch bench_batch
# One sweep run scalar, in lanes, on 2 threads, 2 MPI ranks and 2 shards: throughput and efficiency.
scale=(--repeats 5)
[ $mode = quick ] && scale+=(--quick)
# The options each step's command took in this mode (the paper's table of provenance prints them).
{
  echo "bodypoint study (every recipe): ${q[*]:-no option}"
  echo "bodypoint work-precision: ${wp[*]:-no option}"
  echo "bodypoint work-precision --by-tol: ${by_tol[*]:-no option}"
  echo "bench_steps, bench_batch: ${bench[*]}"
  echo "scripts/ensemble-scaling.sh: ${scale[*]}"
} > "$results/build_options.txt"
scaling() {
  scripts/ensemble-scaling.sh "${scale[@]}" --build "${BODYPOINT_BUILD_DIR:-build}" --csv "$results/scaling.csv" \
    > "$results/scaling.md"
}
step scaling scaling

# The catalogue: the scripts group methods by the families it gives (paper/catalogue.py).
"$bin" methods --csv > "$results/methods.csv.tmp"
mv "$results/methods.csv.tmp" "$results/methods.csv"

# How long the results took (the paper states it beside its grids): the sum of the steps' wall times,
# and in how many sittings.
awk -v n="$sittings" '{ s += $2 } END { printf "%.0f %d\n", s, n }' "$stages" > "$results/build_seconds.txt"

out=paper/build
mkdir -p "$out"
"$py" paper/make_figures.py "$results" "$out/figures"
"$py" paper/make_macros.py "$results" "$out/generated" "$mode" "$out/figures"
cp paper/bodypoint.tex paper/bodypoint.bib "$out/"
(cd "$out" && latexmk -pdf -interaction=nonstopmode -halt-on-error bodypoint.tex > latexmk.out 2>&1) || {
  tail -40 "$out/latexmk.out" >&2
  echo "paper/build.sh: LaTeX failed; the log is $out/bodypoint.log" >&2
  exit 1
}
echo "paper/build.sh: $out/bodypoint.pdf ($mode, results in $(cut -d' ' -f1 "$results/build_seconds.txt") s over $sittings sitting(s); in $results)"
