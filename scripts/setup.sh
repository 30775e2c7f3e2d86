#!/usr/bin/env bash
# Installs what thermotwin needs on Debian 12 (idempotent, non-interactive), configures and builds
# in build/. Usage:
#   scripts/setup.sh [--with-calculix] [--with-fuzz] [--build-type Release|Debug] [--build-dir DIR]
#                    [--sanitize] [--target T]...
# --target builds only T (e.g. thermotwin, without the tests); by default everything is built.
# Where Debian's packages cannot be installed together (python3-paraview against python3-vtk9,
# which libvtk9-dev needs) or apt reports unmet dependencies, it stops before building and says
# what conflicts and how to proceed.
set -euo pipefail
cd "$(dirname "$0")/.."

with_calculix=0; with_fuzz=0; build_type=Release; build_dir=build; sanitize=OFF; targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --with-calculix) with_calculix=1 ;;
    --with-fuzz) with_fuzz=1 ;;
    --build-type) build_type="$2"; shift ;;
    --build-dir) build_dir="$2"; shift ;;
    --sanitize) sanitize=ON ;;
    --target) targets+=(--target "$2"); shift ;;
    *) echo "setup.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done

packages=(build-essential cmake pkg-config libeigen3-dev libsuitesparse-dev libopenblas0-pthread
  libvtk9-dev libtet1.5-dev libcgal-dev libtomlplusplus-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev python3-minimal python3-numpy python3-matplotlib python3-jsonschema
  libtorch-dev clang-format)
[ "$with_calculix" = 1 ] && packages+=(calculix-ccx python3-vtk9)
[ "$with_fuzz" = 1 ] && packages+=(clang-14 libfuzzer-14-dev libclang-rt-14-dev)

installed() {
  dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"
}

# What to do when apt cannot install the build dependencies beside what is installed.
how_to_proceed() {
  echo "setup: how to proceed, one of:" >&2
  if installed python3-paraview; then
    cat >&2 <<'HINT'
  - remove Debian's ParaView Python scripting, then run this script again:
      apt-get remove python3-paraview    (the paraview GUI stays; only its Python scripting goes)
  - for ParaView with Python (pvpython), use Kitware's own binaries (paraview.org/download): they
    bring their own VTK and Python and do not conflict with Debian's libvtk9-dev
HINT
  else
    cat >&2 <<'HINT'
  - remove or upgrade the installed package that apt names above (apt-get install -s PACKAGE
    shows what apt would do), then run this script again
HINT
  fi
  cat >&2 <<'HINT'
  - build in a clean container, e.g.
      docker run --rm -it -v "$PWD":/src -w /src debian:12 bash scripts/quickstart.sh run
HINT
}

missing=()
for p in "${packages[@]}"; do
  installed "$p" || missing+=("$p")
done

# Debian's python3-paraview (ParaView's Python scripting) declares Conflicts: python3-vtk9, and
# libvtk9-dev depends on python3-vtk9: apt would stop inside its resolver with "unmet
# dependencies". Say so before asking apt.
needs_vtk_python=0
for p in "${missing[@]}"; do
  case "$p" in libvtk9-dev|python3-vtk9) needs_vtk_python=1 ;; esac
done
if [ "$needs_vtk_python" = 1 ] && installed python3-paraview; then
  echo "setup: cannot install libvtk9-dev: it needs python3-vtk9, which conflicts with" \
    "python3-paraview (installed: Debian's ParaView Python scripting). apt cannot hold both." >&2
  how_to_proceed
  exit 1
fi

if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  # apt-get waits for the dpkg lock up to this many seconds instead of failing at once.
  apt_opts=(-o DPkg::Lock::Timeout=600 -y -q --no-install-recommends)
  [ "$(id -u)" = 0 ] && sudo_cmd=() || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get -o DPkg::Lock::Timeout=600 update -q
  apt_log=$(mktemp)
  trap 'rm -f "$apt_log"' EXIT
  if ! "${sudo_cmd[@]}" apt-get install "${apt_opts[@]}" "${missing[@]}" 2>&1 | tee "$apt_log"; then
    if grep -q "unmet dependencies" "$apt_log"; then
      echo "setup: apt cannot install the build dependencies beside what is installed;" \
        "apt's reason:" >&2
      # apt's lines after "have unmet dependencies:" up to its final "E:" verdict.
      sed -n '/unmet dependencies/,/^E:/p' "$apt_log" | sed 's/^/  /' >&2
      how_to_proceed
    else
      echo "setup: apt-get install failed (its output is above)" >&2
    fi
    exit 1
  fi
fi

jobs=$(nproc)
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE="$build_type" -DTT_SANITIZE="$sanitize"
cmake --build "$build_dir" -j "$jobs" "${targets[@]}"
