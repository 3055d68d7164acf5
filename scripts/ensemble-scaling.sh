#!/usr/bin/env bash
# bodypoint: throughput and parallel efficiency of one sweep run every way the tool can run it: the
# scalar loop, vector lanes (batches), 2 threads, 2 MPI ranks, and 2 shards merged. Prints a table
# (wall time of one run each, trajectory-steps per second, speed-up and efficiency against the same
# mode on one core) and checks that every way wrote the same CSV (wall_s aside).
# usage: scripts/ensemble-scaling.sh [--quick] [--build DIR] [--csv FILE] [--repeats N]
#   --quick: n = 25000 instead of the thesis's 250000; --build: the build tree (default build);
#   --csv: also write the table as CSV (paper/build.sh does); --repeats: rounds of every mode, interleaved
#   (default 1; paper/build.sh takes 5): the table gives each mode's median wall time, the spread
#   (interquartile range over the median) and the share of the cores other processes used meanwhile
#   (/proc/stat's busy time less this script's children's CPU time), by which paper/timing_rule.py
#   judges the time. Run it on an otherwise idle machine.
set -euo pipefail
cd "$(dirname "$0")/.."
build=build
csv=""
steps=250000
repeats=1
while (($#)); do
  case "$1" in
    --quick) steps=25000 ;;
    --build) build="$2"; shift ;;
    --csv) csv="$2"; shift ;;
    --repeats) repeats="$2"; shift ;;
    *) echo "usage: scripts/ensemble-scaling.sh [--quick] [--build DIR] [--csv FILE] [--repeats N]" >&2; exit 2 ;;
  esac
  shift
done
bp="$build/bin/bodypoint"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# 40 distances x 2 launch distances x 4 methods at h = 1e-4: three with batch kernels and one
# time-transformed method (always scalar) whose cost varies with the encounter.
sweep=(sweep --grid d=5:200:5 --grid L=200,600 --methods lp-y4,rk4,thesis-fr4,logh-kl6 --steps "$steps")
trajectories=$((40 * 2 * 4))

strip() { awk -F, 'BEGIN { OFS = "," } /^#/ { next } !col { for (i = 1; i <= NF; i++) if ($i == "wall_s") col = i; print; next }
                   { $col = ""; print }' "$1"; }
now() { date +%s.%N; }
source scripts/contention.sh
measured="$work/measured.txt"  # mode, wall seconds, share of the cores others used
run() {  # name, then the command
  local name="$1" t0 share; shift
  t0="$(now)"
  contention_start
  "$@" || return 1
  share="$(contention_share)"
  awk -v m="$name" -v a="$(now)" -v b="$t0" -v o="$share" 'BEGIN { printf "%s %.6f %s\n", m, a - b, o }' >> "$measured"
}
shards() {
  "$bp" "${sweep[@]}" --threads 1 --shard 1/2 --out "$work/s1.rows" &
  "$bp" "${sweep[@]}" --threads 1 --shard 2/2 --out "$work/s2.rows"
  wait
  "$bp" merge --input "$work/s1.rows" "$work/s2.rows" --out "$work/shards2.csv"
}

have_mpi=0
command -v mpirun >/dev/null 2>&1 && have_mpi=1
for ((round = 1; round <= repeats; round++)); do
  run scalar1 "$bp" "${sweep[@]}" --no-simd --threads 1 --out "$work/scalar1.csv"
  run simd1 "$bp" "${sweep[@]}" --threads 1 --out "$work/simd1.csv"
  run simd2 "$bp" "${sweep[@]}" --threads 2 --out "$work/simd2.csv"
  if [[ $have_mpi = 1 ]]; then
    run mpi2 mpirun -np 2 --oversubscribe "$bp" "${sweep[@]}" --out "$work/mpi2.csv" || true
    # What mpirun itself costs: starting and ending 2 ranks around a sweep of two 10-step tasks.
    run mpi2-startup mpirun -np 2 --oversubscribe "$bp" sweep --grid d=5,10 --methods lp-y4 --steps 10 \
      --out "$work/startup.csv" || true
  fi
  rm -f "$work/s1.rows" "$work/s2.rows" "$work/shards2.csv"
  run shards2 shards
done
# Per mode: repeats, median wall time, spread (interquartile range over the median), the share of the
# cores others used during the median repeat; quartiles by linear interpolation between the sorted repeats.
declare -A secs reps spread others
while read -r m n w sp o; do
  secs[$m]="$w"; reps[$m]="$n"; spread[$m]="$sp"; others[$m]="$o"
done < <(sort -k1,1 -k2,2g "$measured" | awk '
  function q(a, n, p,   x, i) { x = 1 + (n - 1) * p; i = int(x); return i >= n ? a[n] : a[i] + (x - i) * (a[i + 1] - a[i]) }
  function flush(   med) { if (!n) return; med = q(w, n, 0.5); printf "%s %d %.6f %.4f %.4f\n", m, n, med, (q(w, n, 0.75) - q(w, n, 0.25)) / med, o[int((n + 1) / 2)] }
  $1 != m { flush(); m = $1; n = 0 }
  { n++; w[n] = $2; o[n] = $3 }
  END { flush() }')

for f in simd1 simd2 mpi2 shards2; do
  [[ -f "$work/$f.csv" ]] || continue
  cmp -s <(strip "$work/scalar1.csv") <(strip "$work/$f.csv") || { echo "FAIL: $f differs from the scalar run" >&2; exit 1; }
done
echo "sweep: ${sweep[*]} ($trajectories trajectories)"
"$bp" methods | tail -n 1
echo "every mode wrote the scalar run's CSV (wall_s aside)"
printf '| mode | cores | wall s (median of %d) | spread | others used | trajectory-steps/s | speed-up vs scalar | parallel efficiency |\n|---|---|---|---|---|---|---|---|\n' "$repeats"
[[ -z "$csv" ]] || echo "mode,cores,wall_s,traj_steps_per_s,speedup_vs_scalar,parallel_efficiency,repeats,spread,others_share" > "$csv.tmp"
for m in scalar1 simd1 simd2 mpi2 shards2; do
  [[ -n "${secs[$m]:-}" ]] || continue
  cores=1; base="${secs[simd1]}"
  case $m in scalar1) base="${secs[scalar1]}";; simd2|mpi2|shards2) cores=2;; esac
  # Efficiency: the same mode's one-core time over cores x this time (lanes on one core for simd2, mpi2, shards2).
  row="$(awk -v m="$m" -v c="$cores" -v s="${secs[$m]}" -v sc="${secs[scalar1]}" -v b="$base" -v n="$trajectories" -v k="$steps" \
    'BEGIN { printf "%s,%d,%.3f,%.4g,%.3f,%.3f", m, c, s, n * k / s, sc / s, b / (c * s) }')"
  IFS=, read -r _ _ wall rate speed eff <<< "$row"
  awk -v m="$m" -v c="$cores" -v w="$wall" -v r="$rate" -v sp="$speed" -v e="$eff" -v v="${spread[$m]}" -v o="${others[$m]}" \
    'BEGIN { printf "| %s | %d | %.2f | %.0f %% | %.0f %% | %.3g | %.2fx | %.0f%% |\n", m, c, w, 100 * v, 100 * o, r, sp, 100 * e }'
  [[ -z "$csv" ]] || echo "$row,${reps[$m]},${spread[$m]},${others[$m]}" >> "$csv.tmp"
done
if [[ -n "${secs[mpi2-startup]:-}" ]]; then
  awk -v s="${secs[mpi2-startup]}" 'BEGIN { printf "mpirun start-up and shut-down of 2 ranks (a sweep of two 10-step tasks): %.2f s\n", s }'
  [[ -z "$csv" ]] || awk -v s="${secs[mpi2-startup]}" -v r="${reps[mpi2-startup]}" -v sp="${spread[mpi2-startup]}" \
    -v o="${others[mpi2-startup]}" 'BEGIN { printf "mpi2-startup,2,%.3f,,,,%d,%s,%s\n", s, r, sp, o }' >> "$csv.tmp"
fi
[[ -z "$csv" ]] || mv "$csv.tmp" "$csv"
