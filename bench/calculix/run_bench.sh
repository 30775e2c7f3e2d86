#!/bin/sh
# SB-1 against CalculiX (see run_bench.py for what it compares). From anywhere:
#   bench/calculix/run_bench.sh [--repeats 3] [--skip-elastic] [--elastic-order 1|2] ...
# Results: bench/work/calculix/result.json (git-ignored).
set -eu
exec /usr/bin/python3 "$(dirname "$0")/run_bench.py" "$@"
