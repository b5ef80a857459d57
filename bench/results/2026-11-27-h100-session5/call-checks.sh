#!/usr/bin/env bash
# 2026-11-27 (session 5), one H100, the same machine as call-thesis.sh: the session's final kernels
# (the thesis's roulette rule in volpt's throughput; the lat-long map's sample/pdf and the rough
# dielectric's eval no longer forced inline) against main before the session (session 4's bundle,
# 90f1b80's code, carried by an earlier call to /tmp/old/volpt):
# 1. ab-bin.sh: regeneration-sk on the five scenes, before/after/before/after, median of 3;
# 2. strategies.sh's checks (every strategy against the CPU, fast against exact, memcheck, racecheck);
# 3. startup.py with the final binary.
#   OUT=$OUT bash bench/results/2026-11-27-h100-session5/call-checks.sh
set -uo pipefail
ROOT=$PWD
B=$ROOT/.dev/s6
R=$OUT
[ -f "$B/bin/volpt.gz" ] && gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
cd "$B"
BEFORE=/tmp/old/volpt STRATEGIES=regeneration-sk OUT=/tmp/r timeout 180 bash ab-bin.sh > /tmp/r-ab.out 2>&1
cp /tmp/r/ab-bin.txt "$R/ab-bin.txt" 2>/dev/null; cut -c16-90 "$R/ab-bin.txt" | tail -n 20
OUT=/tmp/r/checks SKIP_BENCH=1 T=60 RACECHECK_T=120 timeout 330 bash strategies.sh > /tmp/r/checks.out 2>&1
cp /tmp/r/checks/summary.txt "$R/checks-summary.txt"
echo "checks: $(grep -c '^== PASS' /tmp/r/checks/summary.txt) passed, $(grep -c '^== FAIL' /tmp/r/checks/summary.txt) failed"
grep '^== FAIL' /tmp/r/checks/summary.txt | cut -c1-300 | head
OUT=/tmp/su timeout 40 python3 startup.py bin/volpt 7 > "$R/startup.txt" 2>&1; grep median "$R/startup.txt"
