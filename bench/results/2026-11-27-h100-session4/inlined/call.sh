#!/usr/bin/env bash
# 2026-11-27, one H100: after the rough boundary's next-event estimation was inlined
# (`interact_with_boundary`, `RoughDielectric::eval` and the map's `sample`/`pdf` always inlined: CI's
# ptx_entries test had found 408-744-byte local-memory frames in every lat-long, rough-dielectric
# kernel). Bundle carried as .dev/s5; the binary of ecf4511 in /tmp/old, the Mitsuba 3 wheels unpacked,
# by earlier calls on the same machine.
# 1. estimator.sh's measurement again: envmap-cube, path tracing against nee, four strategies;
# 2. Mitsuba 3 against volpt on envmap-cube, with path tracing (the default) and with nee;
# 3. ab-bin.sh: before/after on the five scenes;
# 4. strategies.sh's checks (every strategy against the CPU, memcheck, racecheck).
#   OUT=$OUT bash bench/results/2026-11-27-h100-session4/call-inlined.sh
set -uo pipefail
ROOT=$PWD
B=$ROOT/.dev/s5
R=$OUT  # files land in inlined/
gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
ln -sfn "$B" "$ROOT/bundle"
cd "$B"
S=scenes/envmap-cube/scene.xml
./bin/volpt scene generate scenes > /dev/null
for est in pt nee; do for st in auto regeneration-sk naive-sk streaming-sk; do
    echo "== $est $st"
    ./bin/volpt bench $S --backend cuda --estimator $est --strategy $st --spp 100 --trials 3 --json 2>/dev/null \
        | python3 -c "import json,sys; r=json.load(sys.stdin); print({k: r[k] for k in r if k in ('time_median_s','segments_per_s','paths_per_s','strategy')})"
done; done 2>&1 | tee "$R/estimator.txt"
cd "$ROOT"
for est in pt nee; do
    OUT=/tmp/r-$est MODE=gpu SCENES=envmap-cube VOLPT_RENDER_ARGS="--estimator $est" timeout 100 bash bench/peers/mitsuba3/device.sh > "$R/mitsuba-$est.log" 2>&1
    cp /tmp/r-$est/peers/results.md "$R/mitsuba-results-$est.md" 2>/dev/null
    tail -n 1 "$R/mitsuba-results-$est.md" | cut -d'|' -f2,8-14
done
cd "$B"
BEFORE=/tmp/old/volpt STRATEGIES=regeneration-sk OUT=/tmp/r timeout 200 bash ab-bin.sh > /tmp/r-ab.out 2>&1
cp /tmp/r/ab-bin.txt "$R/ab-bin.txt" 2>/dev/null; cut -c16-80 "$R/ab-bin.txt" | tail -n 20
OUT=/tmp/r/checks SKIP_BENCH=1 T=60 RACECHECK_T=120 timeout 340 bash strategies.sh > /tmp/r/checks.out 2>&1
cp /tmp/r/checks/summary.txt "$R/checks-summary.txt"
echo "checks: $(grep -c '^== PASS' /tmp/r/checks/summary.txt) passed, $(grep -c '^== FAIL' /tmp/r/checks/summary.txt) failed"
grep '^== FAIL' /tmp/r/checks/summary.txt | cut -c1-300 | head
