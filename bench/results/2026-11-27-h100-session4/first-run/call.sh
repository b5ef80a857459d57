#!/usr/bin/env bash
# 2026-11-27T00:05Z, one H100, the FIRST device run on main after the envmap-variance and
# parts-files merges (bundle carried as .dev/s4, bin/volpt gzipped; the binary of ecf4511, the
# previous main, left in /tmp/old by an earlier call that carried it as .dev/old):
# 1. ab-bin.sh: the previous binary against this one, regeneration-sk, five scenes, two rounds
#    (the kernels now hold the rough boundary's next-event estimation, off on these scenes);
# 2. strategies.sh's checks, no benchmark: every strategy against the CPU on the seven scenes
#    (naive-sk and naive-mk bit-identical), fast against exact math, memcheck, racecheck.
#   OUT=$OUT bash bench/results/2026-11-27-h100-session4/call-1.sh
set -uo pipefail
ROOT=$PWD
B=$ROOT/.dev/s4
R=$OUT
gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
ln -sfn "$B" "$ROOT/bundle"
cd "$B"
BEFORE=/tmp/old/volpt STRATEGIES=regeneration-sk OUT=/tmp/r timeout 200 bash ab-bin.sh > /tmp/r-ab.out 2>&1
cp /tmp/r/ab-bin.txt "$R/ab-bin.txt" 2>/dev/null; tail -n 25 "$R/ab-bin.txt"
OUT=/tmp/r/checks SKIP_BENCH=1 T=60 RACECHECK_T=120 timeout 340 bash strategies.sh > /tmp/r/checks.out 2>&1
cp /tmp/r/checks/summary.txt "$R/checks-summary.txt"
echo "checks: $(grep -c '^== PASS' /tmp/r/checks/summary.txt) passed, $(grep -c '^== FAIL' /tmp/r/checks/summary.txt) failed"
grep '^== FAIL' /tmp/r/checks/summary.txt | head
