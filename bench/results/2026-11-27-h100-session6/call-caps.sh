#!/usr/bin/env bash
# 2026-11-27 (session 6), one H100, the session's bundle (.dev/s7 as in call-ab.sh): regeneration-sk
# with the compiler's registers against a cap of 64 (`--max-registers 64`), the GPU defaults otherwise,
# on the seven scenes of the Mitsuba comparison and the thesis's two scenes (with the thesis's
# roulette and without roulette, as thesis-efficiency.sh runs them), two alternating rounds, median of 3.
#   OUT=$OUT bash bench/results/2026-11-27-h100-session6/call-caps.sh
set -uo pipefail
B=$PWD/.dev/s7
[ -f "$B/bin/volpt.gz" ] && gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
cd "$B"
./bin/volpt scene generate scenes > /dev/null
python3 thesis/gen_scenes.py /tmp/ts > /dev/null 2>&1
D=$PWD/data
SCENES=(
    "cube-null|scenes/homogeneous-cube/scene.xml -Dboundary=null"
    "cube|scenes/homogeneous-cube/scene.xml"
    "cgg-logo|scenes/cgg-logo/scene.xml"
    "ad|scenes/ad/scene.xml"
    "smoke|scenes/smoke/scene.xml -Ddata=$D"
    "bucky|scenes/bucky/scene.toml -Ddata=$D"
    "envmap-cube|scenes/envmap-cube/scene.xml"
    "thesis-cgg-rr|/tmp/ts/cgg_logo/volpath_bsdf.xml --roulette throughput --rr-depth 0 --resolution 400x400"
    "thesis-cgg-none|/tmp/ts/cgg_logo/volpath_bsdf.xml --rr-depth -1 --resolution 400x400"
    "thesis-ad-rr|/tmp/ts/ad/volpath_bsdf.xml --roulette throughput --rr-depth 0 --resolution 400x400"
    "thesis-ad-none|/tmp/ts/ad/volpath_bsdf.xml --rr-depth -1 --resolution 400x400"
)
echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader) regeneration-sk, 100 spp, median of 3" | tee "$OUT/caps.txt"
for round in 1 2; do for e in "${SCENES[@]}"; do
    name=${e%%|*}; args=${e#*|}
    for cap in "" "--max-registers 64"; do
        timeout 60 ./bin/volpt bench $args --spp 100 --backend cuda --strategy regeneration-sk $cap --trials 3 --json 2>/dev/null \
          | python3 -c "import json,sys; r=json.load(sys.stdin); print(f\"round $round {'$name':<16} {'cap 64' if '$cap' else 'compiler':<9} {r['time_median_s']*1e3:8.2f} ms\")" | tee -a "$OUT/caps.txt"
    done
done; done
