#!/usr/bin/env bash
# Several configurations (binary and flags) timed side by side in one call: `volpt bench` on each
# scene, the configurations alternated within each of ROUNDS rounds, and one line per scene with
# every configuration's median and its ratio to the first one's.
#
#   CONFIGS="before|bin/volpt-before|
#   after|bin/volpt|
#   after-96|bin/volpt|--max-registers 96" bash bench/device/configs-ab.sh
#
# CONFIGS: one configuration a line, `label|binary|flags` (flags after `--backend cuda`; none: the
# defaults). SCENES: `name:file:flags` lines (default: the grey grid scenes in the any-layout
# kernels, --bricked, and sparse bucky.vdb). SPP (100), TRIALS (3), ROUNDS (2).
# Output: $OUT/configs-ab.txt; each bench's JSON under $OUT/json/.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT/json"
SPP=${SPP:-100}; TRIALS=${TRIALS:-3}; ROUNDS=${ROUNDS:-2}
SCENES=${SCENES:-"smoke-bricked:scenes/smoke/scene.xml:-Ddata=$PWD/data --bricked
bucky-bricked:scenes/bucky/scene.toml:-Ddata=$PWD/data --bricked
cgg-logo-bricked:scenes/cgg-logo/scene.xml:--bricked
vdb-bucky-sparse:scenes/vdb/bucky.toml:"}
mapfile -t configs < <(printf '%s\n' "${CONFIGS:?CONFIGS: label|binary|flags lines}" | sed '/^[[:space:]]*$/d')
report=$OUT/configs-ab.txt
log() { echo "$*" | tee -a "$report"; }
first_bin=$(cut -d'|' -f2 <<<"${configs[0]}")
chmod +x bin/* 2>/dev/null
"$first_bin" scene generate scenes </dev/null >/dev/null 2>&1
log "== configs-ab $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -n 1); spp $SPP, trials $TRIALS, rounds $ROUNDS"
for c in "${configs[@]}"; do log "config $c"; done
while IFS=: read -r name file params; do
    [ -n "$name" ] || continue
    for round in $(seq "$ROUNDS"); do
        for c in "${configs[@]}"; do
            IFS='|' read -r label bin flags <<<"$c"
            json=$OUT/json/$name-$label-$round.json
            # shellcheck disable=SC2086
            timeout 300 "$bin" bench "$file" $params --spp "$SPP" --backend cuda $flags --trials "$TRIALS" --json </dev/null >"$json" 2>"$OUT/json/$name-$label-$round.log" \
                || log "FAIL $name $label round $round: $(tail -n 2 "$OUT/json/$name-$label-$round.log" | tr '\n' ' ')"
        done
    done
    labels=$(for c in "${configs[@]}"; do cut -d'|' -f1 <<<"$c"; done | tr '\n' ' ')
    python3 - "$OUT/json" "$name" "$ROUNDS" $labels <<'PY' | tee -a "$report"
import json, statistics, sys
folder, name, rounds, labels = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4:]
medians = {}
for label in labels:
    times = []
    for r in range(1, rounds + 1):
        try:
            times.append(json.load(open(f"{folder}/{name}-{label}-{r}.json"))["time_median_s"] * 1e3)
        except (OSError, ValueError, KeyError):
            pass
    medians[label] = statistics.median(times) if times else float("nan")
base = medians[labels[0]]
print(f"{name:<18}", "  ".join(f"{l} {m:8.2f} ms ({m / base:5.3f})" for l, m in medians.items()))
PY
done <<<"$SCENES"
