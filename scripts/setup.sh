#!/usr/bin/env bash
# Installs what thermotwin needs on Debian 12 (idempotent, non-interactive), configures and builds
# in build/. Usage:
#   scripts/setup.sh [--with-calculix] [--with-fuzz] [--build-type Release|Debug] [--build-dir DIR]
#                    [--sanitize]
set -euo pipefail
cd "$(dirname "$0")/.."

with_calculix=0; with_fuzz=0; build_type=Release; build_dir=build; sanitize=OFF
while [ $# -gt 0 ]; do
  case "$1" in
    --with-calculix) with_calculix=1 ;;
    --with-fuzz) with_fuzz=1 ;;
    --build-type) build_type="$2"; shift ;;
    --build-dir) build_dir="$2"; shift ;;
    --sanitize) sanitize=ON ;;
    *) echo "setup.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done

packages=(build-essential cmake pkg-config libeigen3-dev libsuitesparse-dev libopenblas0-pthread
  libvtk9-dev libtet1.5-dev libcgal-dev libtomlplusplus-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev python3-minimal python3-numpy python3-matplotlib libtorch-dev)
[ "$with_calculix" = 1 ] && packages+=(calculix-ccx python3-vtk9)
[ "$with_fuzz" = 1 ] && packages+=(clang-14 libfuzzer-14-dev libclang-rt-14-dev)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  # apt-get waits for the dpkg lock up to this many seconds instead of failing at once.
  apt_opts=(-o DPkg::Lock::Timeout=600 -y -q --no-install-recommends)
  [ "$(id -u)" = 0 ] && sudo_cmd=() || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get -o DPkg::Lock::Timeout=600 update -q
  "${sudo_cmd[@]}" apt-get install "${apt_opts[@]}" "${missing[@]}"
fi

jobs=$(nproc)
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE="$build_type" -DTT_SANITIZE="$sanitize"
cmake --build "$build_dir" -j "$jobs"
