#!/usr/bin/env bash
# thermotwin compensate's throughput: LINES synthetic samples at 1 kHz (default 10^6; time_s, a
# speed, six temperatures and two displacement columns it ignores) through a fit.json whose two
# targets are a distributed-lag model with the speed (600 s and 3600 s lags: 21 terms) and a least
# squares model on three sensors, the kinds fit --data chooses. Run one at a time, with nice:
#   bench/compensate_throughput.sh [LINES] [OUT_DIR]
# Prints lines/s for a file read to its end (--in FILE --until-eof), for a pipe on standard input,
# and for a pipe with --flush (a write per line), each the best of three.
# Then the physics observer (compensate --rom): ROM_LINES (default 20000) samples at 1 kHz of the
# sensors ROM_SENSORS (default T17,T18,T16,T53,T54) and the speed through the reduced model of
# ROM_CASE (default cases/sb1_coarse.toml; built with reduce --quick-validation into
# OUT_DIR/rom_<case> unless there), read from a file to its end with the default 1 s filter period,
# beside the same stream's first ROM_EVERY_LINES samples (default a tenth) with every sample
# assimilated and a 10-line stream (the start: case, mesh check, model), each best of three;
# ROM_LINES=0 skips it. GM-1 (every sample there costs about 70 ms):
#   ROM_CASE=cases/gm1_coarse.toml ROM_SENSORS=R08,R02,R05,R04 ROM_EVERY_LINES=600 \
#     bench/compensate_throughput.sh
source "$(dirname "$0")/common.sh"
lines=${1:-1000000}
out=${2:-$(mktemp -d)}
mkdir -p "$out"
# A hand-made fit.json in the form io::model_json writes (coefficients in um/K and um/rpm).
/usr/bin/python3 - "$out/fit.json" <<'PY'
import json, sys
sensors = ["T1", "T2", "T3", "T4", "T5", "T6"]
base = ["dT[%s]" % s for s in sensors] + ["d[speed_rpm]"]
lag_terms = base + ["lp%ds(%s)" % (tau, b) for tau in (600, 3600) for b in base]
def target(name, kind, settings, sens, inputs, terms):
    return {"target": name, "chosen": {
        "coefficients": {"kind": kind, "settings": settings, "sensors": sens,
                         "operating_inputs": inputs, "intercept_um": 0.25,
                         "terms": [{"name": t, "um_per_K": 0.1 * (k + 1) * (-1) ** k}
                                   for k, t in enumerate(terms)]},
        "test": {"S_um": {"a": 1.1, "b": 0.9}}}}
doc = {"format": "thermotwin-fit/1", "targets": [
    target("dz", "distributed_lag", {"inputs": True, "ridge_lambda": 1e-4,
                                     "time_constants_s": [600, 3600]}, sensors, ["speed_rpm"],
           lag_terms),
    target("dx", "least_squares", {}, sensors[:3], [], ["dT[%s]" % s for s in sensors[:3]])]}
json.dump(doc, open(sys.argv[1], "w"), indent=1)
PY
awk -v n="$lines" 'BEGIN {
  print "time_s,speed_rpm,T1,T2,T3,T4,T5,T6,dz,dx";
  for (i = 0; i < n; i++) {
    t = i * 0.001;
    printf "%.3f,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.3f,%.3f\n", t, (i % 600000 < 400000) ? 8000 : 0,
      20 + 0.00001 * i, 21 + 0.3 * sin(t), 22 + 0.2 * cos(t / 3), 20.5 + 0.1 * sin(t / 7),
      20 + 0.000002 * i, 19.5 + 0.05 * sin(t / 11), 0.001 * i, -0.0005 * i
  }
}' > "$out/stream.csv"
file_run() { "$bin" compensate --model "$out/fit.json" --in "$out/stream.csv" --until-eof --out "$out/live.csv"; }
pipe_run() { cat "$out/stream.csv" | "$bin" compensate --model "$out/fit.json" > "$out/live_pipe.csv"; }
flush_run() { cat "$out/stream.csv" | "$bin" compensate --model "$out/fit.json" --flush > "$out/live_flush.csv"; }
for mode in file pipe flush; do
  t=$(best ${mode}_run)
  printf '%-5s %d lines in %.3f s: %.0f lines/s\n' "$mode" "$lines" "$t" \
    "$(/usr/bin/python3 -c "print($lines / $t)")"
done
cmp -s "$out/live.csv" "$out/live_pipe.csv" && cmp -s "$out/live.csv" "$out/live_flush.csv" ||
  { echo "outputs differ between the modes" >&2; exit 1; }
echo "statuses: $(cut -d, -f6 "$out/live.csv" | sort | uniq -c | tr '\n' ' ')"
rom_lines=${ROM_LINES:-20000}
[ "$rom_lines" -gt 0 ] || exit 0
rom_case=${ROM_CASE:-$here/cases/sb1_coarse.toml}
rom_sensors=${ROM_SENSORS:-T17,T18,T16,T53,T54}
rom_dir="$out/rom_$(basename "$rom_case" .toml)"
if [ ! -f "$rom_dir/reduced_model.json" ]; then
  "$bin" reduce "$rom_case" --out "$rom_dir" --quick-validation --quiet
fi
# The speed switches between 4000 and 0 rpm every 4 and 2 s, with +-10 rpm of noise on every
# sample (a read-back speed): the filter period's time mean takes it.
rom_stream() {  # rom_stream LINES FILE
  awk -v n="$1" -v sensors="$rom_sensors" 'BEGIN {
    srand(7);
    k = split(sensors, s, ",");
    printf "time_s,speed_rpm";
    for (j = 1; j <= k; j++) printf ",%s", s[j];
    printf "\n";
    for (i = 0; i < n; i++) {
      t = i * 0.001;
      printf "%.3f,%.1f", t, ((i % 6000 < 4000) ? 4000 : 0) + (rand() - 0.5) * 20;
      for (j = 1; j <= k; j++) printf ",%.4f", 20 + 0.0001 * i / j + 0.01 * sin(t * j);
      printf "\n";
    }
  }' > "$2"
}
# The filter's reference: every sample assimilated, on ROM_EVERY_LINES samples (a tenth).
every_lines=${ROM_EVERY_LINES:-$(( rom_lines / 10 > 10 ? rom_lines / 10 : 10 ))}
echo "rom: $(basename "$rom_case")"
period_and_every rom --filter-every-s "$rom_lines" "$every_lines" rom_stream "$out" --rom "$rom_dir"
