#!/usr/bin/env bash
# calibrate --case on the reduced model (the default) against the full-order model (--full), on the
# same measured runs, one after the other:
#   bench/calibration_twin_vs_full.sh CASE DATA_DIR OUT [reduced-only]
# DATA_DIR holds run_0, run_1, ... (bench_calibration_generate writes them, with truth.json): the
# last run is the test run, the others train. Prints per model the wall time and peak memory
# (GNU time), the order, the claimed effects and the test RMS before and after, then the ratio of
# the wall times. `reduced-only` skips the full-order run (on a large mesh it takes long).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${THERMOTWIN:-$here/build/thermotwin}
case_file=${1:?case file}
data=${2:?measured runs folder}
out=${3:?output folder}
only=${4:-}
runs=("$data"/run_*)
[ ${#runs[@]} -ge 3 ] || { echo "expected at least 3 runs in $data" >&2; exit 2; }
test_run=${runs[-1]}
train=("${runs[@]:0:${#runs[@]}-1}")
mkdir -p "$out"
models=(reduced)
[ "$only" = reduced-only ] || models+=(full)
for m in "${models[@]}"; do
  flag=()
  [ "$m" = full ] && flag=(--full)
  /usr/bin/time -v -o "$out/time_$m.txt" "$bin" calibrate --case "$case_file" --train "${train[@]}" \
    --test "$test_run" --out "$out/$m" "${flag[@]}" 2> "$out/log_$m.txt"
done
/usr/bin/python3 - "$out" "$data" "${models[@]}" <<'PY'
import json, re, sys, os
out, data, models = sys.argv[1], sys.argv[2], sys.argv[3:]
truth = os.path.join(data, "truth.json")
if os.path.exists(truth):
    t = json.load(open(truth))
    print(f"truth: {t['kind']} magnitude {t['magnitude']:.4g} target '{t.get('target', '')}'")
wall = {}
for m in models:
    text = open(os.path.join(out, f"time_{m}.txt")).read()
    h, mi, s = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([\d.]+)", text).groups()
    wall[m] = 3600 * int(h or 0) + 60 * int(mi) + float(s)
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", text).group(1)) / 1e6
    c = json.load(open(os.path.join(out, m, "calibration.json")))
    md = c["model"]
    claims = ", ".join(f"{e['kind']} ({e['name']})" for e in c["effects"]) or "none"
    b, a = c["before"], c["after"]
    print(f"{m}: wall {wall[m]:.1f} s, peak RSS {rss:.2f} GB, order {md['order']} of "
          f"{md['nodes']} nodes, model build {md.get('build_s', 0):.1f} s")
    print(f"  claimed: {claims}")
    print(f"  test RMS: T {b['temperature_rms_K']:.4g} -> {a['temperature_rms_K']:.4g} K, "
          f"u {b['displacement_rms_um']:.4g} -> {a['displacement_rms_um']:.4g} um")
if "full" in wall:
    print(f"full / reduced wall time: {wall['full'] / wall['reduced']:.2f}")
PY
