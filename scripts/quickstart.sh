#!/usr/bin/env bash
# The README's quick start. On a fresh Debian 12 machine, as root:
#   bash scripts/quickstart.sh run    install what is missing, build thermotwin alone (not the
#                                     tests), run SB-1 (P-1) into out/sb1
#   bash scripts/quickstart.sh test   install what is missing, build everything, run the test
#                                     suite (ctest)
set -euo pipefail
cd "$(dirname "$0")/.."
what="${1:-run}"
case "$what" in
  run)
    scripts/setup.sh --target thermotwin
    build/thermotwin run cases/sb1.toml --out out/sb1
    echo "quickstart: results in out/sb1 (open out/sb1/fields.pvd in ParaView)"
    ;;
  test)
    scripts/setup.sh
    # Studies labelled 'long' run outside the suite: ctest -L long.
    (cd build && ctest --output-on-failure -LE long -j "$(nproc)" --timeout 1200)
    ;;
  *)
    echo "usage: scripts/quickstart.sh run|test" >&2
    exit 2
    ;;
esac
