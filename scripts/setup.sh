#!/usr/bin/env bash
# bodypoint: install the build dependencies (Debian 12 packages) if missing, then configure and build
# into ./build (Release). Safe to run again: it installs nothing that is already there and rebuilds
# incrementally. Set BODYPOINT_WERROR=ON to treat warnings as errors (CI does).
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(cmake ninja-build g++ git libeigen3-dev libboost-dev libboost-program-options-dev
          libgtest-dev libbenchmark-dev libtomlplusplus-dev libgsl-dev python3-matplotlib python3-numpy)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DBODYPOINT_WERROR="${BODYPOINT_WERROR:-OFF}" >/dev/null
cmake --build build --parallel "$(nproc)"
