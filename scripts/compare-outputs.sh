#!/usr/bin/env bash
# Compare two kin2grf builds on every development trial: estimate's CSV, GRF .mot and JSON and
# validate's JSON, byte for byte (the JSON without its wall-clock timings). For a change that
# must not change results (a refactor, a faster solver), run with the build before and after:
#   bash scripts/compare-outputs.sh OLD_KIN2GRF NEW_KIN2GRF [DATA_DIR]
# Prints one line per trial and output; exit status 1 when any output differs, with the largest
# relative difference of its numbers ("text" when more than numbers differ). The CSV and .mot
# carry 6 significant digits: a change of round-off (another factorisation) flips a last digit
# now and then, a relative difference of at most 5e-6 per cell; the JSON's full-precision
# numbers show it near 1e-15.
set -euo pipefail
cd "$(dirname "$0")/.."
OLD=$1 NEW=$2 DATA=${3:-../shared/data}
[ -x "$OLD" ] && [ -x "$NEW" ] || { echo "compare-outputs: give two kin2grf executables" >&2; exit 2; }
[ -d "$DATA" ] || { echo "compare-outputs: no data folder $DATA" >&2; exit 2; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
PY=/usr/bin/python3
strip_timing() {  # the JSON without keys whose value is a wall time
  "$PY" -c 'import json,sys
def clean(x):
    if isinstance(x, dict): return {k: clean(v) for k, v in x.items() if not (k.startswith("seconds") or k.endswith("_seconds") or k in ("frames_per_s", "timing"))}
    if isinstance(x, list): return [clean(v) for v in x]
    return x
print(json.dumps(clean(json.load(open(sys.argv[1]))), sort_keys=True, indent=1))' "$1"
}
differ=0
grep -v '^#' scripts/trials.txt | grep . | sed "s#DATA#$DATA#g" | while IFS='|' read -r activity lab name rest; do
  args=$(echo "$rest" | sed -E 's/--plates [^ ]+//')
  plates=$(echo "$rest" | grep -oE -- '--plates [^ ]+' || true)
  for side in old new; do
    exe=$OLD; [ $side = new ] && exe=$NEW
    d="$WORK/$side/$name"; mkdir -p "$d"
    # shellcheck disable=SC2086
    "$exe" estimate $args --csv "$d/e.csv" -o "$d/e.mot" --json "$d/e.json" >/dev/null 2>&1 || echo "estimate failed" >"$d/e.csv"
    # shellcheck disable=SC2086
    "$exe" validate $args $plates --json "$d/v.json" >/dev/null 2>&1 || echo "validate failed" >"$d/v.json"
    for j in e v; do
      strip_timing "$d/$j.json" >"$d/$j.clean.json" 2>/dev/null || echo "no JSON" >"$d/$j.clean.json"
    done
  done
  for f in e.csv e.mot e.clean.json v.clean.json; do
    if cmp -s "$WORK/old/$name/$f" "$WORK/new/$name/$f"; then
      echo "same     $name $f"
    else
      # Not byte-identical: the largest relative difference of the numbers, the rest compared as text.
      verdict=$("$PY" - "$WORK/old/$name/$f" "$WORK/new/$name/$f" <<'PYEOF'
import json, math, re, sys
a, b = (open(f).read() for f in sys.argv[1:3])
num = re.compile(r"-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")
ta, tb = num.split(a), num.split(b)
na, nb = num.findall(a), num.findall(b)
if ta != tb or len(na) != len(nb):
    print("text"); sys.exit()
worst = 0.0
for x, y in zip(na, nb):
    if x != y:
        fx, fy = float(x), float(y)
        worst = max(worst, abs(fx - fy) / max(abs(fx), abs(fy), 1e-12))
print("%.1e" % worst)
PYEOF
)
      echo "DIFFERS  $name $f (largest relative difference of a number: $verdict)"
      touch "$WORK/differ"
    fi
  done
done
[ -e "$WORK/differ" ] && exit 1
echo "all outputs identical"
