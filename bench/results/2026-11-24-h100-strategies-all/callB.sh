# 2026-11-24T23:09Z, call B: every strategy's checks (strategies.sh, no benchmark), then naive-sk and
# naive-mk benchmarked at 16 spp.
set -uo pipefail
cd "$(dirname "$0")"
for b in bin/volpt bin/volpt-base; do [ -f $b.gz ] && gunzip -f $b.gz; chmod +x $b 2>/dev/null; done
R=$OUT; mkdir -p /tmp/r
OUT=/tmp/r/checks SKIP_BENCH=1 T=90 bash strategies.sh > /tmp/r/checks.out 2>&1
grep -E "FAIL|failures" /tmp/r/checks/summary.txt; echo "checks passed: $(grep -c '^== PASS' /tmp/r/checks/summary.txt)"
OUT=/tmp/r/naive STRATEGIES="naive-sk naive-mk" FAST_STRATEGIES="naive-sk naive-mk" EXACT_STRATEGIES="naive-sk naive-mk" \
  SKIP_CHECKS=1 SKIP_CAPS=1 TRIALS=1 T=120 BENCH_ARGS="--spp 16" bash strategies.sh > /tmp/r/naive.out 2>&1
cat /tmp/r/naive/bench.txt
cp /tmp/r/checks/summary.txt $R/checks-summary.txt; cp /tmp/r/naive/bench.txt $R/naive-bench.txt
