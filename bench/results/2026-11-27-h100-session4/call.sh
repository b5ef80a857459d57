#!/usr/bin/env bash
# 2026-11-27, one H100: main after the envmap-variance and parts-files merges, with the rough
# boundary's next-event estimation compiled out under a constant environment (the first run,
# first-run/, found the kernels of those scenes 1.6-1.7x slower with it compiled in). Bundle carried
# as .dev/s4 (bin/volpt gzipped); the binary of ecf4511, the previous main, left in /tmp/old by a
# call that carried it as .dev/old; the Mitsuba 3 wheels unpacked by a call that carried bundle-peer/.
# 1. ab-bin.sh: the previous binary against this one, regeneration-sk, five scenes, two rounds;
# 2. strategies.sh's checks, no benchmark: every strategy against the CPU on the seven scenes
#    (naive-sk and naive-mk bit-identical), fast against exact math, memcheck, racecheck;
# 3. facade-check.sh: chunked and resumed renders bit-identical to one render, auto cached;
# 4. Mitsuba 3 cuda_ad_rgb against volpt's GPU defaults on envmap-cube, 400x400, 100 spp, time to
#    equal error (bench/peers/mitsuba3/device.sh, MODE=gpu), the scene whose estimator changed.
#   OUT=$OUT bash bench/results/2026-11-27-h100-session4/call.sh
set -uo pipefail
ROOT=$PWD
B=$ROOT/.dev/s4
R=$OUT
gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
ln -sfn "$B" "$ROOT/bundle"
cd "$B"
BEFORE=/tmp/old/volpt STRATEGIES=regeneration-sk OUT=/tmp/r timeout 200 bash ab-bin.sh > /tmp/r-ab.out 2>&1
cp /tmp/r/ab-bin.txt "$R/ab-bin.txt" 2>/dev/null; tail -n 20 "$R/ab-bin.txt" | cut -c16-80
OUT=/tmp/r/checks SKIP_BENCH=1 T=60 RACECHECK_T=120 timeout 340 bash strategies.sh > /tmp/r/checks.out 2>&1
cp /tmp/r/checks/summary.txt "$R/checks-summary.txt"
echo "checks: $(grep -c '^== PASS' /tmp/r/checks/summary.txt) passed, $(grep -c '^== FAIL' /tmp/r/checks/summary.txt) failed"
grep '^== FAIL' /tmp/r/checks/summary.txt | cut -c1-300 | head
OUT=/tmp/r/facade timeout 120 bash facade-check.sh > "$R/facade-check.txt" 2>&1
echo "facade: $(grep -c '^== PASS' "$R/facade-check.txt") passed, $(grep -c '^== FAIL' "$R/facade-check.txt") failed"
cd "$ROOT"
OUT=/tmp/r MODE=gpu SCENES=envmap-cube timeout 100 bash bench/peers/mitsuba3/device.sh > "$R/mitsuba.log" 2>&1
cp /tmp/r/peers/results.md "$R/mitsuba-results.md" 2>/dev/null
mkdir -p "$R/mitsuba-json" && cp /tmp/r/peers/*.json "$R/mitsuba-json/" 2>/dev/null
cat "$R/mitsuba-results.md"
