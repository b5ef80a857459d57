#!/usr/bin/env bash
# 2026-11-27 (session 6), one H100: the negligible-weight roulette (volpt_core::path::NEGLIGIBLE_WEIGHT)
# against main before it, then Mitsuba 3 on the two homogeneous cubes with the new binary.
# Carried: .dev/s7 = the session's device bundle (bin/volpt gzipped, scenes, data, scripts) with
# ab/1-before.ptx.gz (main at 7212cc1, session 5's kernels) and ab/2-after.ptx.gz (this change), both
# cut to the regeneration-sk kernels by bench/device/ptx_cut.py. The Mitsuba wheels were unpacked by
# an earlier call on the same machine (`bash bench/peers/mitsuba3/device.sh` with bundle-peer carried).
# 1. ab.sh twice: five scenes, regeneration-sk, the defaults (fast math, stochastic lookups), median of 3;
# 2. segments per path of each kernel on the two cubes;
# 3. bench/peers/mitsuba3/device.sh, MODE=gpu, the two cubes.
#   OUT=$OUT bash bench/results/2026-11-27-h100-session6/call-ab.sh
set -uo pipefail
ROOT=$PWD
B=$ROOT/.dev/s7
[ -f "$B/bin/volpt.gz" ] && gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
gunzip -f "$B"/ab/*.ptx.gz
cd "$B"
for r in 1 2; do OUT=/tmp/ab$r timeout 200 bash ab.sh > /dev/null 2>&1; cat /tmp/ab$r/ab.txt; done | tee "$OUT/ab.txt" | cut -c1-110
for p in 1-before 2-after; do for b in "" "-Dboundary=null"; do
    VOLPT_PTX=ab/$p.ptx ./bin/volpt bench scenes/homogeneous-cube/scene.xml $b --backend cuda --strategy regeneration-sk \
        --trials 1 --json 2>/dev/null | python3 -c "import json,sys; r=json.load(sys.stdin); print(f\"$p cube $b: {r['segments']/r['paths']:.2f} segments/path, {r['time_median_s']*1e3:.2f} ms\")"
done; done | tee "$OUT/segments.txt"
cd "$ROOT"
rm -rf bundle && ln -s .dev/s7 bundle
MODE=gpu SCENES="homogeneous-cube homogeneous-cube-null" timeout 400 bash bench/peers/mitsuba3/device.sh > "$OUT/mitsuba.log" 2>&1
cat "$OUT/peers/results.md" 2>/dev/null | cut -c1-400
