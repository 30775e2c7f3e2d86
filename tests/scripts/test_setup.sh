#!/usr/bin/env bash
# scripts/setup.sh and scripts/quickstart.sh against fake dpkg-query, apt-get, sudo, cmake, ctest
# and thermotwin placed first on PATH, in a copy of the scripts: nothing is installed or built.
#   bash tests/scripts/test_setup.sh [SOURCE_DIR]
# Checks: Debian's python3-paraview stops the set-up before apt with what conflicts and how to
# proceed; apt's "unmet dependencies" is explained the same way; the normal path configures and
# builds (everything, or only --target); quickstart's run builds only thermotwin, test everything.
set -uo pipefail
src="$(cd "${1:-$(dirname "$0")/../..}" && pwd)"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
expect_in() {  # expect_in FILE TEXT WHAT
  grep -qF -- "$2" "$1" || fail "$3: '$2' not in $(basename "$1"):"$'\n'"$(cat "$1")"
}
expect_not_in() {
  ! grep -qF -- "$2" "$1" || fail "$3: '$2' in $(basename "$1"):"$'\n'"$(cat "$1")"
}

# The fakes log their arguments to $FAKE_LOG, one call a line.
bin="$work/bin"
mkdir -p "$bin"
cat > "$bin/dpkg-query" <<'FAKE'
#!/usr/bin/env bash
# dpkg-query -W -f='${Status}' PKG: installed when PKG is in $FAKE_INSTALLED (or it is "all").
pkg="${!#}"
for p in $FAKE_INSTALLED; do
  if [ "$p" = all ] || [ "$p" = "$pkg" ]; then printf 'install ok installed'; exit 0; fi
done
echo "dpkg-query: no packages found matching $pkg" >&2
exit 1
FAKE
cat > "$bin/apt-get" <<'FAKE'
#!/usr/bin/env bash
echo "apt-get $*" >> "$FAKE_LOG"
case " $* " in
  *" install "*)
    case "${FAKE_APT:-ok}" in
      unmet)
        cat <<'APT'
Reading package lists...
Building dependency tree...
Some packages could not be installed. This may mean that you have
requested an impossible situation.

The following information may help to resolve the situation:

The following packages have unmet dependencies:
 python3-paraview : Conflicts: python3-vtk9 but 9.1.0+really9.1.0+dfsg2-5+deb12u1 is to be installed
APT
        echo "E: Unable to correct problems, you have held broken packages." >&2
        exit 100 ;;
      broken)
        echo "E: Could not get lock /var/lib/dpkg/lock-frontend" >&2
        exit 100 ;;
    esac ;;
esac
exit 0
FAKE
for tool in cmake ctest; do
  printf '#!/usr/bin/env bash\necho "%s $*" >> "$FAKE_LOG"\n' "$tool" > "$bin/$tool"
done
printf '#!/usr/bin/env bash\nexec "$@"\n' > "$bin/sudo"
chmod +x "$bin"/*

# A copy of the scripts, so that their `cd` lands in a scratch tree with a fake build/thermotwin.
repo="$work/repo"
mkdir -p "$repo/scripts" "$repo/build"
cp "$src/scripts/setup.sh" "$src/scripts/quickstart.sh" "$repo/scripts/"
printf '#!/usr/bin/env bash\necho "thermotwin $*" >> "$FAKE_LOG"\n' > "$repo/build/thermotwin"
chmod +x "$repo/build/thermotwin"

# run NAME INSTALLED APT SCRIPT ARGS...: runs a script with the fakes; sets out, err, log, rc.
run() {
  local name="$1" installed="$2" apt="$3"
  shift 3
  out="$work/$name.out" err="$work/$name.err" log="$work/$name.log"
  : > "$log"
  FAKE_LOG="$log" FAKE_INSTALLED="$installed" FAKE_APT="$apt" PATH="$bin:$PATH" \
    bash "$repo/scripts/$1" "${@:2}" > "$out" 2> "$err"
  rc=$?
}

# 1. python3-paraview installed, libvtk9-dev missing: stop before apt, say what and how.
run paraview "python3-paraview cmake" ok setup.sh
[ "$rc" = 1 ] || fail "paraview: exit $rc, expected 1"
expect_in "$err" "python3-paraview" paraview
expect_in "$err" "python3-vtk9" paraview
expect_in "$err" "libvtk9-dev" paraview
expect_in "$err" "apt-get remove python3-paraview" paraview
expect_in "$err" "paraview.org/download" paraview
expect_in "$err" "docker run" paraview
expect_not_in "$log" "apt-get" paraview
expect_not_in "$log" "cmake" paraview

# 2. apt reports unmet dependencies: its reason is printed, then how to proceed; no build.
run unmet "cmake" unmet setup.sh
[ "$rc" = 1 ] || fail "unmet: exit $rc, expected 1"
expect_in "$log" "apt-get install" unmet
expect_in "$err" "apt's reason" unmet
expect_in "$err" "python3-paraview : Conflicts: python3-vtk9" unmet
expect_in "$err" "E: Unable to correct problems" unmet
expect_in "$err" "how to proceed" unmet
expect_not_in "$log" "cmake" unmet

# 3. apt fails for another reason: it says so, no hint about conflicts, no build.
run broken "cmake" broken setup.sh
[ "$rc" = 1 ] || fail "broken: exit $rc, expected 1"
expect_in "$err" "apt-get install failed" broken
expect_not_in "$err" "how to proceed" broken
expect_not_in "$log" "cmake" broken

# 4. The normal path: what is missing is installed, then everything is configured and built.
run normal "cmake" ok setup.sh
[ "$rc" = 0 ] || fail "normal: exit $rc:"$'\n'"$(cat "$err")"
expect_in "$log" "apt-get -o DPkg::Lock::Timeout=600 update -q" normal
expect_in "$log" "libvtk9-dev" normal
expect_in "$log" "cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DTT_SANITIZE=OFF" normal
expect_in "$log" "cmake --build build -j $(nproc)" normal
expect_not_in "$log" "--target" normal

# 5. All installed (python3-paraview too, the VTK packages already in): no apt; --target builds
#    only that target.
run target "all" ok setup.sh --target thermotwin
[ "$rc" = 0 ] || fail "target: exit $rc:"$'\n'"$(cat "$err")"
expect_not_in "$log" "apt-get" target
expect_in "$log" "cmake --build build -j $(nproc) --target thermotwin" target

# 6. quickstart run builds only thermotwin and runs SB-1; quickstart test builds everything.
run quick_run "all" ok quickstart.sh run
[ "$rc" = 0 ] || fail "quickstart run: exit $rc:"$'\n'"$(cat "$err")"
expect_in "$log" "cmake --build build -j $(nproc) --target thermotwin" "quickstart run"
expect_in "$log" "thermotwin run cases/sb1.toml --out out/sb1" "quickstart run"
run quick_test "all" ok quickstart.sh test
[ "$rc" = 0 ] || fail "quickstart test: exit $rc:"$'\n'"$(cat "$err")"
expect_not_in "$log" "--target" "quickstart test"
expect_in "$log" "ctest --output-on-failure -LE long" "quickstart test"

if [ "$failures" -gt 0 ]; then
  echo "test_setup: $failures failure(s)" >&2
  exit 1
fi
echo "test_setup: all checks passed"
