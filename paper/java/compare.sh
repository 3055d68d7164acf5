#!/usr/bin/env bash
# Runs the thesis's own Java solvers (its published repository, github.com/axothy/Body-point-dynamics,
# checked out at THESIS_REPO) at the harnesses' settings of `bodypoint study --quick --name published`
# and writes how far bodypoint's rows are from them to paper/java_agreement.csv, which the paper quotes.
#
#   paper/java/compare.sh THESIS_REPO
#
# Needs a JDK (javac, java) and a built bodypoint (BODYPOINT_BUILD_DIR, default build/). The thesis's
# code imports JavaFX's Point3D only as a vector; Point3D.java here is a stand-in with the same formulas,
# so no JavaFX is needed. Nothing of the thesis's code is kept in this repository.
set -euo pipefail
cd "$(dirname "$0")/../.."
[ $# -eq 1 ] || { echo "usage: paper/java/compare.sh THESIS_REPO" >&2; exit 2; }
src="$1/src/main/java"
[ -d "$src/ru/axothy/mechanics" ] || { echo "compare.sh: no thesis sources under $src" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
m="$src/ru/axothy/mechanics"
s="$m/equationsolvers"
javac -nowarn -d "$tmp/classes" paper/java/Point3D.java paper/java/Harness.java "$m/tensors/Tensor.java" \
  "$m"/bodypoint/*.java "$m/energy/Energy.java" "$m/energy/BodyPointEnergy.java" \
  "$m/motion/Equation.java" "$m/motion/BodyPointEquation.java" "$m/motion/BodyPointEquationWithoutTensors.java" \
  "$s/SymplecticEulerForSystem.java" "$s/VerletMethodForSystem.java" "$s/RuthMethodForSystem.java" \
  "$s/YoshidaMethodForSystem.java" "$s/YoshidaMethod6thOrder.java" "$s/RungeKutta4MethodForSystem.java" \
  "$s/AdamsBashfortForSystem.java" 2> >(grep -v '^Note:' >&2)
"${BODYPOINT_BUILD_DIR:-build}/bin/bodypoint" study --quick --name published --results "$tmp/results"
commit=$(git -C "$1" rev-parse HEAD 2>/dev/null || echo unknown)
/usr/bin/python3 paper/java/compare.py "$tmp/results" "$tmp/classes" "$tmp/agreement.csv"
{
  echo "# paper/java/compare.sh: bodypoint $(git rev-parse --short HEAD) against the thesis's Java solvers (axothy/Body-point-dynamics $commit)"
  cat "$tmp/agreement.csv"
} > paper/java_agreement.csv.tmp
mv paper/java_agreement.csv.tmp paper/java_agreement.csv
echo "wrote paper/java_agreement.csv ($(($(wc -l < paper/java_agreement.csv) - 2)) runs)"
