#!/usr/bin/env bash
# ctest PythonExamplesDrawTheirFigures: each examples/python script, quick, writes a PDF figure.
# usage: tests/python/run_examples.sh PYTHON   (PYTHONPATH: the module's folder)
set -euo pipefail
python="$1"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for f in thesis_figure scattering; do
  "$python" "examples/python/$f.py" "$out/$f.pdf" --quick
  head -c 5 "$out/$f.pdf" | grep -q '%PDF-' || { echo "$f.py wrote no PDF" >&2; exit 1; }
done
