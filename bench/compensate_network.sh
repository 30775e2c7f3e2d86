#!/usr/bin/env bash
# thermotwin compensate with a network (cnn_bigru_attention) as a target's chosen model: how many
# samples a second it takes at 1 kHz, at the default network period (--network-every-s 1) and with
# the network evaluated at every sample (--network-every-s 0), and whether a replayed held-out run
# gives compensation.csv's predictions.
#   bench/compensate_network.sh [LINES] [OUT_DIR]
# Writes a 30 h training run and a 5.5 h held-out run a minute apart (the spindle at 2500 rpm for
# 4 of every 6 hours; sensors a, b, c lag it by 20, 50 and 100 min; drift p linear in them and the
# speed, q = -1.5 um/K dc + 0.4 um/K^2 da^2, which no linear candidate has), fits them with
# fit --data --network --quick (about 80 s), then streams LINES samples at 1 kHz (default 2*10^6)
# of the same columns, from a file to its end, and a hundredth of them with every sample evaluated;
# each best of three, the start (fit.json, the network file) measured apart on a 10-line stream.
source "$(dirname "$0")/common.sh"
lines=${1:-2000000}
out=${2:-$(mktemp -d)}
mkdir -p "$out"
/usr/bin/python3 - "$out" <<'PY'
import json, math, os, random, sys
out = sys.argv[1]
def low_pass(t, x, tau):
    y, prev = [x[0]], x[0]
    for i in range(1, len(t)):
        a = math.exp(-(t[i] - t[i - 1]) / tau)
        prev = a * prev + (1 - a) * x[i]
        y.append(prev)
    return y
def run(name, hours, seed):
    rnd = random.Random(seed)
    n = int(hours * 60)
    t = [60.0 * i for i in range(n)]
    on = [1.0 if (ti % 21600) < 14400 and ti >= 600 else 0.0 for ti in t]
    amb = [20 + 0.4 * math.sin(ti / 20000 + seed) for ti in t]
    temp = [[amb[i] + (6 - c) * v for i, v in enumerate(low_pass(t, on, lag))]
            for c, lag in enumerate((1200.0, 3000.0, 6000.0))]
    rise = [[v - col[0] for v in col] for col in temp]
    lp_b = low_pass(t, rise[1], 2400.0)
    d = os.path.join(out, name)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "data.csv"), "w") as f:
        f.write("time_s,speed_rpm,a,b,c,p,q\n")
        for i in range(n):
            p = 2 * rise[0][i] + lp_b[i] + 0.001 * 2500 * on[i] + rnd.gauss(0, 0.1)
            q = -1.5 * rise[2][i] + 0.4 * rise[0][i] ** 2 + rnd.gauss(0, 0.1)
            f.write(f"{t[i]:g},{2500 * on[i]:g},{temp[0][i]:.6f},{temp[1][i]:.6f},"
                    f"{temp[2][i]:.6f},{p:.6f},{q:.6f}\n")
    meta = {"format": "thermal-measurement/1", "machine": "synthetic", "run": name,
            "time_unit": "s", "temperature_unit": "degC", "displacement_unit": "um",
            "sensors": [{"id": s, "position": None} for s in "abc"],
            "displacements": [{"id": s, "point": None, "direction": None} for s in "pq"],
            "inputs": [{"id": "speed_rpm", "unit": "rpm"}]}
    json.dump(meta, open(os.path.join(d, "meta.json"), "w"), indent=1)
run("train", 30.0, 1)
run("test", 5.5, 2)
PY
if [ ! -f "$out/fit/fit.json" ]; then
  "$bin" fit --data "$out/train" --test "$out/test" --out "$out/fit" --quick --network --quiet
fi
/usr/bin/python3 - "$out/fit/fit.json" <<'PY'
import json, sys
for t in json.load(open(sys.argv[1]))["targets"]:
    c = t["chosen"]["coefficients"]
    extra = ""
    if c["kind"] == "cnn_bigru_attention":
        extra = (f" (window {c['window_steps']} x {c['window_spacing_s']:g} s, best epoch "
                 f"{c['training']['best_epoch']})")
    print(f"target {t['target']}: {c['kind']}{extra}")
PY
# The replay: the held-out run through compensate against compensation.csv.
"$bin" compensate --model "$out/fit/fit.json" --in "$out/test/data.csv" --until-eof \
  --out "$out/replay.csv"
/usr/bin/python3 - "$out/fit/compensation.csv" "$out/replay.csv" <<'PY'
import csv, sys
off = {(r["target"], float(r["time_s"])): float(r["predicted_um"]) for r in csv.DictReader(open(sys.argv[1]))}
worst, n = 0.0, 0
for r in csv.DictReader(open(sys.argv[2])):
    for t in ("p", "q"):
        k = (t, float(r["time_s"]))
        if k in off:
            worst = max(worst, abs(float(r[t + "_predicted_um"]) - off[k])); n += 1
print(f"replay: {n} predictions, largest difference from compensation.csv {worst:.2e} um "
      f"(largest prediction {max(abs(v) for v in off.values()):.2f} um)")
PY
stream() {  # stream LINES FILE: 1 kHz, the columns the fit reads
  awk -v n="$1" 'BEGIN {
    print "time_s,speed_rpm,a,b,c";
    for (i = 0; i < n; i++) {
      t = i * 0.001;
      printf "%.3f,%d,%.5f,%.5f,%.5f\n", t, (i % 6000 < 4000) ? 2500 : 0,
        20 + 0.00002 * i + 0.01 * sin(t), 20 + 0.00001 * i, 20 + 0.000005 * i
    }
  }' > "$2"
}
every_lines=$(( lines / 100 > 10 ? lines / 100 : 10 ))
period_and_every network --network-every-s "$lines" "$every_lines" stream "$out" \
  --model "$out/fit/fit.json"
