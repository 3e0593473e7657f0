#!/usr/bin/env bash
# Robustness of the estimate to what real capture does (issue 10), per development walking trial:
# 2 mm of Gaussian noise on every marker coordinate (8 seeded draws pooled; `kin2grf study noise`), a ground
# shifted by +-1 cm after calibration (`kin2grf study ground-shift`) and the trial cut to its plates' loaded
# span +-0.3 s (`kin2grf study trial-cut`) and the heel markers lost for 0.2 s at every plate stance,
# filled from the markers that move rigidly with them (`kin2grf study marker-gaps`), and the toe markers replaced
# by virtual toes (`kin2grf study toe-ablation`: a set without them), and the subject made dynamically
# similar at 0.6 of its size (`kin2grf study subject-scale`: a child's walk), and the heel or the MT markers
# placed 15 mm further back or forward along the foot (`kin2grf study marker-placement`). Writes docs/ROBUSTNESS.md:
# per trial the per-foot rRMSE (vertical, anterior, COP) at 0 mm and the change in points.
#   bash scripts/robustness.sh [DATA_DIR] [EXTRA ESTIMATE OPTIONS...]
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${1:-../shared/data}
shift || true
[ -d "$DATA" ] || { echo "robustness: no data folder $DATA" >&2; exit 1; }
cmake --preset release >/dev/null
cmake --build --preset release >/dev/null
K=build/release/kin2grf
OUT=out/robustness
mkdir -p "$OUT"
grep -v '^#' scripts/trials.txt | grep '^walking' | sed "s#DATA#$DATA#g" >"$OUT/walking.txt"
# The one default chosen on noisy trials (min_kinematic_cycles): chosen again without each lab, on
# every trial with 2 mm of noise, so that each walk is also scored at its lab's held-out choice.
grep -v '^#' scripts/trials.txt | grep -v '^ *$' | sed "s#DATA#$DATA#g; s#\$# ${*:-}#" >"$OUT/all.txt"
"$K" study min-kinematic-cycles --trial-list "$OUT/all.txt" --cross-validate lab --json "$OUT/cv-floor.json" >/dev/null 2>&1
# A study's rows as JSON (unrounded: the targets are tenths of a point, so differences of the
# printed, rounded figures could be off by 0.1).
study_json() { "$K" study "$1" --trial-list "$2" --json "$3" >/dev/null 2>&1; }
{
  echo "# Robustness to marker noise and ground level (walking)"
  echo
  echo "Made by \`bash scripts/robustness.sh\` $(date -u +%Y-%m-%d) with kin2grf $($K --version | awk '{print $2}')${*:+ and options \`$*\`}."
  echo "Per-foot rRMSE % (mean over the trial's plate stances) with the defaults, and the change in"
  echo "points with 2 mm of Gaussian noise on every marker coordinate (8 seeded draws, the same for every"
  echo "trial, their stances pooled: one draw alone moved subject01's vertical by +0.1 to +2.5 points with"
  echo "the seed) and with the ground shifted by -1 cm and +1 cm after calibration (the change of larger size,"
  echo "with its sign: + is worse), and with the trial cut to its plates' loaded span and 0.3 s around it"
  echo "(\`kin2grf study trial-cut\`: less of the trial to measure the ground, the foot-flat reference and the"
  echo "speed from, and the filters' edges nearer the stances; a treadmill trial keeps its frames), and with"
  echo "both heel markers lost for 0.2 s at the middle of every plate stance (\`kin2grf study marker-gaps\`), their"
  echo "gaps filled from three markers that move rigidly with each (\`--rigid-fill\`, the default; without it every"
  echo "stance is lost), or \"lost\" where the trial keeps fewer stances than as recorded, and with each toe"
  echo "marker replaced by the presets' virtual toes (\`kin2grf study toe-ablation\`: what a lab whose set has no toe"
  echo "marker gets; \"virtual already\" where the trial's set has none), and with the trunk, arm and toe markers all removed"
  echo "(the same study's third row: a lower-body clinical set such as Plug-in Gait's lower body or Helen-Hayes, the sets"
  echo "of the held-out labs), and with that set's MT markers placed 15 mm back and 2 mm of noise, 8 draws (the same study's"
  echo "fourth row: a clinical lab's capture, where Plug-in Gait's and Helen-Hayes' TOE marker stands over the second MT head"
  echo "on the midfoot side of the toes' break; each ablation alone costs a point or less, this measures whether they add"
  echo "up), and with the subject made dynamically similar"
  echo "at 0.6 of its size (\`kin2grf study subject-scale\`: lengths x 0.6, times x sqrt(0.6), forces x 0.6^3, the"
  echo "validation's thresholds alike: a child of about 1.05 m walking the same gait; what changes is owed to a rule"
  echo "that does not scale with the subject), and with the heel markers, then the MT markers, placed 15 mm further"
  echo "back and further forward along the foot (\`kin2grf study marker-placement\`, in the trial and its static trial:"
  echo "where a lab puts them, about a marker's diameter off; the change of larger size of back and forward, with its"
  echo "sign: model 2 places the COP in lengths between these markers, since session 48)."
  echo "Differences of the unrounded figures (the study JSON)."
  echo "Targets (issue 10): noise < 1 point, ground shift < 0.2 points, on every trial. In session 46 (the COP"
  echo "function's centre-of-mass term) OpenCap's walk missed the second at 1 cm lower, +0.4 vertical (each foot's last"
  echo "push-off frame released a frame earlier); since session 47 (the function in heel-MT lengths) it is +0.0 again."
  echo "Camargo's COP with its toe markers removed (+10 points) is its first plate's stance, which fails the registration"
  echo "check with the file's toe marker and passes it with virtual toes: a misregistered plate scored (docs/METHOD-NOTES.md)."
  echo "Held out: the same 2 mm of noise with the stance floor of the noise-lowered kinematic cut-off"
  echo "(\`--min-kinematic-cycles\`, default 3.0, the one default chosen on noisy trials) at the value"
  echo "\`kin2grf study min-kinematic-cycles --cross-validate lab\` chooses without the trial's lab (in brackets)."
  echo
  echo "| trial | vertical | anterior | COP | 2 mm noise: vertical | anterior | COP | +-1 cm ground: vertical | anterior | COP | 2 mm noise, held out: vertical | anterior | COP | cut to the plates +-0.3 s: vertical | anterior | COP | heels lost 0.2 s, filled: vertical | anterior | COP | toe markers removed: vertical | anterior | COP | lower body, virtual toes: vertical | anterior | COP | lower body, MT 15 mm back, 2 mm noise: vertical | anterior | COP | subject x 0.6: vertical | anterior | COP | heels +-15 mm: vertical | anterior | COP | MT heads +-15 mm: vertical | anterior | COP |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
  while IFS= read -r line; do
    name=$(echo "$line" | cut -d'|' -f3)
    lab=$(echo "$line" | cut -d'|' -f2)
    echo "$line ${*:-}" >"$OUT/one.txt"
    study_json noise "$OUT/one.txt" "$OUT/noise.json"
    study_json ground-shift "$OUT/one.txt" "$OUT/shift.json"
    study_json trial-cut "$OUT/one.txt" "$OUT/cut.json"
    study_json marker-gaps "$OUT/one.txt" "$OUT/gaps.json"
    study_json toe-ablation "$OUT/one.txt" "$OUT/toes.json"
    study_json subject-scale "$OUT/one.txt" "$OUT/scale.json"
    study_json marker-placement "$OUT/one.txt" "$OUT/placement.json"
    held=$(/usr/bin/python3 -c 'import json, sys
c = json.load(open(sys.argv[1]))["cross_validation"]["choice_without_lab"][sys.argv[2]].split()[0]
print(0 if c == "off," else c)' "$OUT/cv-floor.json" "$lab")
    echo "$line ${*:-} --min-kinematic-cycles $held" >"$OUT/one.txt"
    study_json noise "$OUT/one.txt" "$OUT/noise-held.json"
    /usr/bin/python3 - "$name" "$OUT/noise.json" "$OUT/shift.json" "$OUT/noise-held.json" "$held" "$OUT/cut.json" "$OUT/gaps.json" "$OUT/toes.json" "$OUT/scale.json" "$OUT/placement.json" <<'PY'
import json, math, sys
name = sys.argv[1]
def rows(path):
    out = {}
    for r in json.load(open(path))["rows"]:
        acts = r["activities"]
        m = next(iter(acts.values()))["rrmse_percent"] if acts else {}
        out[r["setting"]] = [float("nan") if m.get(k) is None else m[k] for k in ("vertical", "anterior", "cop")]  # NaN is null
    return out
noise, shift, held = rows(sys.argv[2]), rows(sys.argv[3]), rows(sys.argv[4])
base, two = noise.get("0 mm noise"), noise.get("2 mm noise")
if not base or any(math.isnan(x) for x in base):
    print(f"| {name} | no complete stance | | | | | | | | | | | | | | | | | | | | | | | | | | | | | | | | | | | |")
    sys.exit()
cells = [f"{x:.1f}" for x in base] + [f"{t - b:+.1f}" for b, t in zip(base, two)]
# The ground: the change of larger size of -1 cm and +1 cm, with its sign (+: worse).
for k in range(3):
    changes = [shift[s][k] - shift["+0 mm"][k] for s in ("-10 mm", "+10 mm")]
    cells.append(f"{max(changes, key=abs):+.1f}")
# Held out: against the same clean figures (no clean trial's cut-off is lowered, so the floor
# leaves them as they are; the held-out run's own 0 mm row says so).
hb, h2 = held["0 mm noise"], held["2 mm noise"]
assert all(abs(a - b) < 1e-9 for a, b in zip(hb, base)), "the stance floor changed a clean trial"
cells += [f"{t - b:+.1f}" for b, t in zip(base, h2)]
cells[-3] += f" ({sys.argv[5]})"
cut = rows(sys.argv[6])
assert all(abs(a - b) < 1e-9 for a, b in zip(cut["as recorded"], base)), "the trial-cut study's first row is not the trial as recorded"
cells += [f"{t - b:+.1f}" for b, t in zip(base, cut["plates' span +-0.3 s"])]
gaps = {r["setting"]: next(iter(r["activities"].values())) for r in json.load(open(sys.argv[7]))["rows"] if r["activities"]}
kept, filled = gaps["as recorded"], gaps.get("heels lost 0.2 s, rigid fill on")
if filled and filled["stances"] == kept["stances"]:
    g = [float("nan") if filled["rrmse_percent"].get(k) is None else filled["rrmse_percent"][k] for k in ("vertical", "anterior", "cop")]
    cells += [f"{t - b:+.1f}" for b, t in zip(base, g)]
else:
    cells += [f"lost ({filled['stances'] if filled else 0} of {kept['stances']})", "", ""]
toes = rows(sys.argv[8])
assert all(abs(a - b) < 1e-9 for a, b in zip(toes["as recorded"], base)), "the toe-ablation study's first row is not the trial as recorded"
ablated = toes["toe markers removed"]
if all(a == b for a, b in zip(ablated, toes["as recorded"])):
    cells += ["virtual already", "", ""]
else:
    cells += [f"{t - b:+.1f}" for b, t in zip(base, ablated)]
cells += [f"{t - b:+.1f}" for b, t in zip(base, toes["lower body, virtual toes"])]
cells += [f"{t - b:+.1f}" for b, t in zip(base, toes["lower body, MT 15 mm back, 2 mm noise"])]
scale = rows(sys.argv[9])
assert all(abs(a - b) < 1e-9 for a, b in zip(scale["as recorded"], base)), "the subject-scale study's first row is not the trial as recorded"
cells += [f"{t - b:+.1f}" for b, t in zip(base, scale["subject x 0.6"])]
placement = rows(sys.argv[10])
assert all(abs(a - b) < 1e-9 for a, b in zip(placement["as recorded"], base)), "the marker-placement study's first row is not the trial as recorded"
# A marker placed further back can put the heel point off the plate's edge: validate then leaves
# the stance out ("partly off the plate"), which is the validation's check, not the estimate.
counts = {r["setting"]: (next(iter(r["activities"].values()))["stances"] if r["activities"] else 0)
          for r in json.load(open(sys.argv[10]))["rows"]}
for which in ("heels", "MT heads"):
    kept = [d for d in ("back", "forward") if counts[f"{which} 15 mm {d}"] == counts["as recorded"]]
    lost = [d for d in ("back", "forward") if d not in kept]
    for k in range(3):
        changes = [placement[f"{which} 15 mm {d}"][k] - base[k] for d in kept]
        cell = f"{max(changes, key=abs):+.1f}" if changes else ""
        if k == 0 and lost:
            cell += (" " if cell else "") + "(" + " and ".join(lost) + ": off the plate)"
        cells.append(cell)
print("| " + name + " | " + " | ".join(cells) + " |")
PY
  done <"$OUT/walking.txt"
} >docs/ROBUSTNESS.md
cat docs/ROBUSTNESS.md
