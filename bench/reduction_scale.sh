#!/usr/bin/env bash
# The reduced basis against mesh size: for each case, nodes, order, build time and peak memory of
# the default basis (block rational Krylov, 0 + 5 shifts, two moments, speeds 0 and 6000 rpm),
# from `bench_solvers_reduction CASE 6000 0 build` under GNU time, one case after the other.
#   bench/reduction_scale.sh [CASE...]   (default: the coarse and default SB-1 and GM-1 cases and
#                                         the refined SB-1 mesh)
# BLAS on one thread, as the CLI runs it. Prints one Markdown table row per case.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bench=${BENCH:-$here/build/bench/bench_solvers_reduction}
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(sb1_coarse gm1_coarse sb1 gm1 sb1_refined)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "| case | nodes | order | basis build [s] | whole bench (mesh, assembly, basis) [s] | peak RSS [GB] | load average at start |"
echo "|---|---|---|---|---|---|---|"
for c in "${cases[@]}"; do
  file=$c
  [ -f "$file" ] || file=$here/cases/$c.toml
  load=$(cut -d' ' -f1 /proc/loadavg)
  OPENBLAS_NUM_THREADS=1 /usr/bin/time -v -o "$tmp/time" "$bench" "$file" 6000 0 build > "$tmp/out"
  nodes=$(sed -n 's/^case [^:]*: \([0-9]*\) nodes.*/\1/p' "$tmp/out")
  order=$(sed -n 's/^basis krylov.* r = *\([0-9]*\), build \([0-9.]*\) s.*/\1/p' "$tmp/out")
  build=$(sed -n 's/^basis krylov.* r = *\([0-9]*\), build \([0-9.]*\) s.*/\2/p' "$tmp/out")
  wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$tmp/time")
  rss=$(awk '/Maximum resident/ {printf "%.2f", $NF / 1048576}' "$tmp/time")
  echo "| $(basename "$file") | $nodes | $order | $build | $wall | $rss | $load |"
done
