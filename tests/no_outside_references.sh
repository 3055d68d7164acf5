#!/usr/bin/env bash
# ctest SelfContained: no tracked file of the project points at material outside the repository (the
# physics is docs/physics.md). usage: no_outside_references.sh SOURCE_DIR
set -euo pipefail
cd "$1"
self=tests/no_outside_references.sh
patterns=(-e '\.\./shared' -e 'PHYSICS\.md' -e 'STYLE\.md' -e 'shared/seed')
if ! git rev-parse --git-dir >/dev/null 2>&1; then echo "not a git checkout: nothing to check"; exit 0; fi
hits=$(git ls-files -z | grep -zv -e '^experiments/viewer/node_modules/' -e "^$self\$" | xargs -0 grep -l -I "${patterns[@]}" || true)
if [ -n "$hits" ]; then
  echo "files that point outside the repository:"; echo "$hits"; exit 1
fi
echo "no tracked file points outside the repository"
