#!/usr/bin/env bash
# The CNN-BiGRU-attention network (seed 004) beside the linear models, on the same groups:
#   bench/network_side_by_side.sh fl  OUT   # data/fl-thermal-measured, the published test window
#   bench/network_side_by_side.sh gm1 OUT   # cases/gm1_coarse.toml, held-out duty cycles
# Runs `thermotwin fit [--data] --network` on 2 threads and prints, per target or channel, the
# chosen model's and the network's held-out S_M and window MAE, the network's training time and
# its median one-window inference time (from fit.json's summary); on GM-1 also the feed axis: the
# one network for every output against the linear model per axis point, and the axis polynomial
# fitted from each one's predictions (fit.json's axis).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${THERMOTWIN:-$here/build/thermotwin}
which=${1:?fl or gm1}
out=${2:?output directory}
export OMP_NUM_THREADS=2 OPENBLAS_NUM_THREADS=1
start=$(date +%s)
case "$which" in
  fl) "$bin" fit --data "$here/data/fl-thermal-measured" --network --out "$out" ;;
  gm1) "$bin" fit "$here/cases/gm1_coarse.toml" --hours "${HOURS:-5}" --network --out "$out" ;;
  *) echo "expected fl or gm1, got '$which'" >&2; exit 2 ;;
esac
echo "wall time: $(( $(date +%s) - start )) s"
python3 - "$out/fit.json" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
def f(v, d=2):
    return "-" if v is None else f"{v:.{d}f}"
print("| target | chosen model | chosen test S_M [um] | network test S_M [um] | chosen window MAE "
      "[um] | network window MAE [um] | published MAE [um] | network training [s] | "
      "network inference [ms] |")
print("|---|---|---|---|---|---|---|---|---|")
for name, s in doc["summary"].items():
    n = s.get("network", {})
    print(f"| {name} | {s['model']} | {f(s['test_sm_um'])} | {f(n.get('test_sm_um'))} | "
          f"{f(s.get('window_mae_continuous_um'))} | {f(n.get('window_mae_continuous_um'))} | "
          f"{f(s.get('published_mae_um'), 3)} | {f(n.get('training_seconds'), 1)} | "
          f"{f(n.get('inference_ms_median'), 3)} |")
ax = doc.get("axis")
if ax:
    # GM-1's feed axis: the one network for every output against the linear model per point, and
    # the axis polynomial fitted from each one's predictions on the test groups.
    net = ax.get("network", {})
    print(f"\none network for all {net.get('outputs', '-')} outputs on {net.get('sensors')}: "
          f"training {f(net.get('training_seconds'), 1)} s, best epoch {net.get('best_epoch')} "
          f"of {net.get('epochs')}")
    print("\n| direction | axis points' mean test S_M, linear [um] | network [um] | uncompensated "
          "std [um] |\n|---|---|---|---|")
    for d in ("dx", "dy", "dz"):
        ts = [v for k, v in ax["targets"].items() if k.endswith("_" + d)]
        mean = lambda key: sum(t[key] for t in ts) / len(ts) if all(t.get(key) is not None for t in ts) else None
        print(f"| {d} | {f(mean('test_sm_um'))} | {f(mean('network_test_sm_um'))} | "
              f"{f(mean('uncompensated_std_um'))} |")
    res = ax["polynomial_residual"]
    print("\n| axis polynomial from | " + " | ".join(f"{d} RMS [um] | {d} max [um]" for d in ("dx", "dy", "dz"))
          + " |\n|---|" + "---|" * 6)
    for src, v in res.items():
        print(f"| {src} | " + " | ".join(f"{f(v[d]['rms_um'])} | {f(v[d]['max_um'])}"
                                          for d in ("dx", "dy", "dz")) + " |")
PY
