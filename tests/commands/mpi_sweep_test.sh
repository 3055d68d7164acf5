#!/usr/bin/env bash
# The sweep under mpirun (issue #14): 2 and 3 ranks write the CSV of a single process (the wall_s
# column aside), a failure on rank 0 before the sweep stops every rank with one error line, and an
# MPI run resumes a journal. usage: mpi_sweep_test.sh MPIEXEC BODYPOINT
set -euo pipefail
mpiexec="$1"
bp="$2"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# Rows of three costs: a far pass, the default scene, and a time-transformed method's close encounter.
args=(sweep --grid d=5:45:20 --grid Kx=-2,2 --methods lp-y4,rk4,logh-kl6,thesis-euler --h 5e-3 --steps 4000)

# A CSV with the wall_s cells blanked (the one column that differs between runs).
strip_wall() {
  awk -F, 'BEGIN { OFS = "," } /^#/ { print; next } !col { for (i = 1; i <= NF; i++) if ($i == "wall_s") col = i; print; next }
           { $col = "W"; print }' "$1"
}
fail() { echo "FAIL: $*" >&2; exit 1; }

"$bp" "${args[@]}" --threads 1 --out "$dir/one.csv"
for np in 2 3; do
  "$mpiexec" -np "$np" "$bp" "${args[@]}" --out "$dir/mpi$np.csv"
  cmp <(strip_wall "$dir/one.csv") <(strip_wall "$dir/mpi$np.csv") || fail "mpirun -np $np differs from one process"
  [[ ! -e "$dir/mpi$np.csv.journal" ]] || fail "the journal of a finished MPI run was left"
  echo "mpirun -np $np: $(grep -vc '^#' "$dir/mpi$np.csv") lines, identical to one process"
done

# A journal of an interrupted run and no --resume: refused on rank 0, every rank stops, one error line.
printf '#bodypoint-rows 1 key=0000000000000000 tasks=1\n' > "$dir/x.csv.journal"
if "$mpiexec" -np 2 "$bp" "${args[@]}" --out "$dir/x.csv" 2> "$dir/err.txt"; then fail "a refused MPI run exited 0"; fi
[[ "$(grep -c 'bodypoint: error:' "$dir/err.txt")" == 1 ]] || { cat "$dir/err.txt"; fail "expected one error line"; }
grep -q 'add --resume' "$dir/err.txt" || fail "the reason is missing: $(cat "$dir/err.txt")"
[[ ! -e "$dir/x.csv" ]] || fail "a refused run wrote its output"

# Resume under MPI: half the rows of a single-process journal, the rest computed by the ranks.
rm "$dir/x.csv.journal"
"$bp" "${args[@]}" --threads 1 --shard 1/2 --out "$dir/half.rows"
cp "$dir/half.rows" "$dir/r.csv.journal"  # a shard's rows file has the journal's format
"$mpiexec" -np 2 "$bp" "${args[@]}" --out "$dir/r.csv" --resume
cmp <(strip_wall "$dir/one.csv") <(strip_wall "$dir/r.csv") || fail "the resumed MPI run differs from one process"
echo "resumed under mpirun -np 2 from a journal of half the rows: identical"
