# 2026-11-24T23:18Z, call C: every strategy but the naive ones benchmarked on every scene (fast
# math; regeneration-sk also exact, and bin/volpt-base, the binary of 900f74e, for before/after).
set -uo pipefail
cd "$(dirname "$0")"
for b in bin/volpt bin/volpt-base; do [ -f $b.gz ] && gunzip -f $b.gz; chmod +x $b 2>/dev/null; done
R=$OUT; mkdir -p /tmp/r
OUT=/tmp/r/bench SKIP_CHECKS=1 SKIP_CAPS=1 TRIALS=3 T=90 EXACT_STRATEGIES="regeneration-sk" \
  FAST_STRATEGIES="regeneration-sk regeneration-warp-sk regeneration-block-sk streaming-sk streaming-sorted-sk sorting-sk streaming-mk" \
  bash strategies.sh > /tmp/r/bench.out 2>&1
cat /tmp/r/bench/bench.txt; grep FAIL /tmp/r/bench/summary.txt
cp /tmp/r/bench/bench.txt $R/bench.txt; cp /tmp/r/bench/summary.txt $R/bench-summary.txt
cp /tmp/r/bench/ptxas-*summary.txt $R/ 2>/dev/null
