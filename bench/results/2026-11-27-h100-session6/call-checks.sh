#!/usr/bin/env bash
# 2026-11-27 (session 6), one H100, right after call-ab.sh: strategies.sh's checks on the session's
# final kernels (every strategy against the CPU on seven scenes, naive-sk bit-identical, fast against
# exact, memcheck, racecheck), carried in .dev/s7 as for call-ab.sh.
#   OUT=$OUT bash bench/results/2026-11-27-h100-session6/call-checks.sh
set -uo pipefail
B=$PWD/.dev/s7
[ -f "$B/bin/volpt.gz" ] && gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
cd "$B"
OUT=/tmp/r/checks SKIP_BENCH=1 T=60 RACECHECK_T=120 timeout 500 bash strategies.sh > /tmp/r-checks.out 2>&1
cp /tmp/r/checks/summary.txt "$OUT/checks-summary.txt"
echo "checks: $(grep -c '^== PASS' /tmp/r/checks/summary.txt) passed, $(grep -c '^== FAIL' /tmp/r/checks/summary.txt) failed"
grep '^== FAIL' /tmp/r/checks/summary.txt | cut -c1-300 | head
