#!/usr/bin/env bash
# tests/python/test_bodypoint.py (test_installs_into_a_fresh_venv_offline...): the two ways README gives to install the module, each into a fresh
# virtual environment in a temporary folder, offline, then docs/guide.md's and README's Python examples
# run by the venv's interpreter from the installed module (not the build tree):
#   pip install .                                   (lib/python/build_backend.py; BODYPOINT_BUILD_DIR
#                                                    reuses this build instead of compiling again)
#   cmake --install BUILD --component python --prefix VENV
# and pip into the user site of PYTHON itself (a temporary PYTHONUSERBASE; Debian's pip needs
# --break-system-packages for it, PEP 668).
# usage: tests/python/install_venv.sh PYTHON SOURCE BUILD
set -euo pipefail
python="$1" source="$2" build="$3"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
examples="$tmp/examples.py"
# Every ```python block of the guide and README, in order, as one script (each block stands alone).
"$python" - "$source" > "$examples" <<'PY'
import pathlib, re, sys
src = pathlib.Path(sys.argv[1])
for doc in ("docs/guide.md", "README.md"):
    for block in re.findall(r"```python\n(.*?)```", (src / doc).read_text(), re.S):
        print(block)
print("import bodypoint, sys; sys.stdout.write(bodypoint.__file__)")
PY
user="$tmp/user"
if "$python" -m pip --version > /dev/null 2>&1; then
  PYTHONUSERBASE="$user" BODYPOINT_BUILD_DIR="$build" "$python" -m pip install --user --break-system-packages \
    --no-index --no-cache-dir --quiet "$source"
  where=$(cd "$source" && PYTHONUSERBASE="$user" env -u PYTHONPATH "$python" "$examples" | tail -n 1)
  case "$where" in
    "$user"/*) echo "user: the examples ran with $where" ;;
    *) echo "user: the examples imported bodypoint from '$where', not from the user site" >&2; exit 1 ;;
  esac
else
  echo "user: skipped, $python has no pip (Debian: python3-pip)"
fi
for way in pip cmake; do
  venv="$tmp/$way"
  "$python" -m venv --system-site-packages "$venv"  # numpy from Debian's python3-numpy
  if [ "$way" = pip ]; then
    BODYPOINT_BUILD_DIR="$build" "$venv/bin/python" -m pip install --no-index --quiet "$source"
  else
    cmake --install "$build" --component python --prefix "$venv" > /dev/null
  fi
  where=$(cd "$source" && env -u PYTHONPATH "$venv/bin/python" "$examples" | tail -c 4096 | tail -n 1)
  case "$where" in
    "$venv"/*) echo "$way: the examples ran with $where" ;;
    *) echo "$way: the examples imported bodypoint from '$where', not from the venv" >&2; exit 1 ;;
  esac
done
