#!/usr/bin/env bash
# Runs one fuzz target for a while on its seed corpus plus the corpus it has grown so far.
#   fuzz/run.sh case|measured|surface|stream [SECONDS=3600] [BUILD_DIR=build-fuzz]
# Findings go to BUILD_DIR/artifacts/<name>/, the log to BUILD_DIR/fuzz_<name>.log. Inputs that
# found bugs are copied by hand to fuzz/regressions/<name>/ (tests/reliability replays them).
set -euo pipefail
cd "$(dirname "$0")/.."
name="$1"; seconds="${2:-3600}"; build="${3:-build-fuzz}"
case "$name" in
  case) target=fuzz_case_reader; dict=fuzz/case.dict ;;
  measured) target=fuzz_measured_data; dict=fuzz/measured.dict ;;
  surface) target=fuzz_surface_reader; dict="" ;;
  stream) target=fuzz_sample_stream; dict="" ;;
  *) echo "usage: fuzz/run.sh case|measured|surface|stream [SECONDS] [BUILD_DIR]" >&2; exit 2 ;;
esac
mkdir -p "$build/corpus/$name" "$build/artifacts/$name"
# 10 s per input is a hang; 2 GB is a leak or an unbounded allocation.
args=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=16384
      -print_final_stats=1 -artifact_prefix="$build/artifacts/$name/")
[ -n "$dict" ] && args+=(-dict="$dict")
exec "$build/$target" "${args[@]}" "$build/corpus/$name" "fuzz/corpus/$name"
