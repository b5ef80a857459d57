#!/usr/bin/env bash
# 2026-11-26, the merged main on one H100, from its device bundle carried as .dev/final (bin/volpt
# gzipped, the full-module PTX copies left out), after a call that carried bundle-peer/ and unpacked
# the Mitsuba 3 wheels (bench/peers/mitsuba3/device.sh, which stops when no bundle is carried):
# 1. strategies.sh's checks, no benchmark: every strategy against the CPU on the seven scenes
#    (naive-sk and naive-mk bit-identical), fast against exact math, memcheck, racecheck;
# 2. facade-check.sh: chunked and resumed renders bit-identical to the render in one go, auto cached;
# 3. startup.py: a 16x16, 1-spp render's process time, five runs, its parts stamped;
# 4. Mitsuba 3 cuda_ad_rgb against volpt's GPU defaults, 400x400, 100 spp, time to equal error
#    (bench/peers/mitsuba3/device.sh, MODE=gpu).
#   OUT=$OUT bash bench/results/2026-11-26-h100-final/call.sh
set -uo pipefail
ROOT=$PWD
B=$ROOT/.dev/final
R=$OUT
gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
ln -sfn "$B" "$ROOT/bundle"
cd "$B"
mkdir -p /tmp/r
OUT=/tmp/r/checks SKIP_BENCH=1 T=60 RACECHECK_T=120 timeout 330 bash strategies.sh > /tmp/r/checks.out 2>&1
cp /tmp/r/checks/summary.txt "$R/checks-summary.txt"
echo "checks: $(grep -c '^== PASS' /tmp/r/checks/summary.txt) passed, $(grep -c '^== FAIL' /tmp/r/checks/summary.txt) failed"
OUT=/tmp/r/facade timeout 120 bash facade-check.sh > "$R/facade-check.txt" 2>&1
echo "facade: $(grep -c '^== PASS' "$R/facade-check.txt") passed, $(grep -c '^== FAIL' "$R/facade-check.txt") failed"
OUT=/tmp/r timeout 60 python3 "$ROOT/bench/device/startup.py" bin/volpt 5 > "$R/startup.txt" 2>&1
tail -n 16 "$R/startup.txt"
cd "$ROOT"
OUT=/tmp/r MODE=gpu timeout 240 bash bench/peers/mitsuba3/device.sh > "$R/mitsuba.log" 2>&1
cp /tmp/r/peers/results.md "$R/mitsuba-results.md" 2>/dev/null
mkdir -p "$R/mitsuba-json" && cp /tmp/r/peers/*.json "$R/mitsuba-json/" 2>/dev/null
cat "$R/mitsuba-results.md" 2>/dev/null | cut -c1-400
