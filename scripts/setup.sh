#!/usr/bin/env bash
# bodypoint: install the build dependencies (Debian 12 packages) if missing, then configure and build
# into ./build (Release). Safe to run again: it installs nothing that is already there and rebuilds
# incrementally. Set BODYPOINT_WERROR=ON to treat warnings as errors (CI does).
#
#   scripts/setup.sh              everything: library, command line, Python module, tests, benchmarks,
#                                 viewer, paper, MPI, sanitizers
#   scripts/setup.sh --minimal    only what the library, the command line and the Python module need
#                                 (no Chromium, TeX, clang, MPI, GoogleTest, Google Benchmark, Node.js);
#                                 run it again without --minimal to add the rest
set -euo pipefail
cd "$(dirname "$0")/.."

minimal=0
case "${1:-}" in
  --minimal) minimal=1 ;;
  "") ;;
  *) echo "usage: scripts/setup.sh [--minimal]" >&2; exit 2 ;;
esac

# The library, the command line and the Python module (pybind11 on Debian's python3, numpy arrays;
# pandas, which docs/guide.md's sweeps use; python3-venv and python3-pip for `pip install .`).
packages=(cmake ninja-build g++ git libeigen3-dev libboost-dev libboost-program-options-dev
          libtomlplusplus-dev libgsl-dev libsundials-dev python3-numpy python3-dev pybind11-dev python3-pandas python3-venv python3-pip)
if ((!minimal)); then
  # Tests and benchmarks (GoogleTest, Google Benchmark, pytest), the figures (matplotlib) and:
  packages+=(libgtest-dev libbenchmark-dev python3-pytest python3-matplotlib
             chromium clang libclang-rt-14-dev texlive-latex-base texlive-latex-recommended latexmk
             libopenmpi-dev openmpi-bin)
fi
# TeX Live (base and recommended LaTeX, about 48 MB to download) and latexmk compile the research
# appendix, paper/build.sh.
# Open MPI (about 12 MB to download) runs a sweep across processes: mpirun -np N bodypoint sweep ...
# clang and its runtime serve the sanitizer build and the libFuzzer targets (scripts/check-sanitizers.sh).
# The viewer (bodypoint view) bundles three.js with esbuild under Node.js; its browser test drives
# Debian's chromium. Debian's nodejs/npm only where no Node.js is installed already.
((minimal)) || command -v npm >/dev/null 2>&1 || packages+=(nodejs npm)
missing=()
for p in "${packages[@]}"; do
  [[ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null)" == "install ok installed" ]] || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The viewer's npm packages, pinned by experiments/viewer/package-lock.json. Optional: without them (no
# npm registry) everything else builds and `bodypoint view` says what is missing.
viewer=experiments/viewer
if ((!minimal)) && { [ ! -f "$viewer/node_modules/.package-lock.json" ] || [ "$viewer/package-lock.json" -nt "$viewer/node_modules/.package-lock.json" ]; }; then
  if ! (cd "$viewer" && npm ci --no-audit --no-fund --loglevel=error >/dev/null 2>&1); then
    echo "setup: warning: npm ci in $viewer failed; bodypoint view and its browser test are left out" >&2
  fi
fi

extra=()
if ((minimal)); then
  extra=(-DBODYPOINT_BUILD_TESTS=OFF -DBODYPOINT_BUILD_BENCH=OFF)
else
  extra=(-DBODYPOINT_BUILD_TESTS=ON -DBODYPOINT_BUILD_BENCH=ON)
fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DBODYPOINT_WERROR="${BODYPOINT_WERROR:-OFF}" "${extra[@]}" >/dev/null
cmake --build build --parallel "$(nproc)"
if ((minimal)); then
  echo "setup: minimal build done (library, build/bin/bodypoint, Python module in build/python);" \
       "scripts/setup.sh without --minimal adds the tests, benchmarks, viewer, paper and MPI" >&2
fi
