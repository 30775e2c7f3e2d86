# Sourced by the bench scripts: strict mode, `here` (the project root), `bin` (the thermotwin
# binary, $THERMOTWIN or the build tree's), and `best "$@"`, which prints the best wall time [s]
# of three runs of the command "$@".
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=${THERMOTWIN:-$here/build/thermotwin}
best() {
  local b=""
  for _ in 1 2 3; do
    local s e
    s=$(date +%s.%N)
    "$@"
    e=$(date +%s.%N)
    b=$(/usr/bin/python3 -c "t = $e - $s; b = '$b'; print(t if not b else min(t, float(b)))")
  done
  echo "$b"
}

# period_and_every LABEL FLAG LINES EVERY_LINES MAKE_STREAM OUT ARGS...: `thermotwin compensate
# ARGS` on LINES samples written by `MAKE_STREAM N FILE` (its default period), on EVERY_LINES of
# them with `FLAG 0` (every sample), and on 10 of them (the start), each best of three, reading
# the files to their end; the outputs go to OUT/live_LABEL.csv and OUT/live_LABEL_every.csv.
# Prints the samples/s after the start, as times 1 kHz, the ratio of the two, and the statuses.
period_and_every() {
  local label=$1 flag=$2 n=$3 ne=$4 make=$5 out=$6
  shift 6
  "$make" "$n" "$out/stream_$label.csv"
  "$make" "$ne" "$out/stream_${label}_every.csv"
  "$make" 10 "$out/stream_${label}_start.csv"
  local t te t0
  t=$(best "$bin" compensate "$@" --in "$out/stream_$label.csv" --until-eof \
    --out "$out/live_$label.csv")
  te=$(best "$bin" compensate "$@" "$flag" 0 --in "$out/stream_${label}_every.csv" --until-eof \
    --out "$out/live_${label}_every.csv")
  t0=$(best "$bin" compensate "$@" --in "$out/stream_${label}_start.csv" --until-eof --out /dev/null)
  /usr/bin/python3 - "$label" "$flag" "$n" "$t" "$ne" "$te" "$t0" <<'PY'
import sys
label, flag = sys.argv[1], sys.argv[2]
n, t, ne, te, t0 = int(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5]), float(sys.argv[6]), float(sys.argv[7])
if t - t0 <= 0.05 * t or te - t0 <= 0.05 * te:
    print(f"{label}: {n} lines in {t:.3f} s, {ne} with {flag} 0 in {te:.3f} s, the start alone "
          f"{t0:.3f} s: the samples' cost is within the start's spread; give more lines")
    sys.exit(0)
rate, rate_every = n / (t - t0), ne / (te - t0)
print(f"{label}, the default period: {n} lines in {t:.3f} s ({n / t:.0f} lines/s with the start "
      f"of {t0:.3f} s), {rate:.0f} samples/s after it: {rate / 1000:.1f} times 1 kHz")
print(f"{label}, every sample ({flag} 0): {ne} lines in {te:.3f} s, {rate_every:.0f} samples/s "
      f"after the start: {rate_every / 1000:.2f} times 1 kHz; the period is "
      f"{rate / rate_every:.1f} times faster")
PY
  echo "statuses ($label): $(awk -F, 'NR > 1 { print $NF }' "$out/live_$label.csv" | sort | uniq -c | tr '\n' ' ')"
}
