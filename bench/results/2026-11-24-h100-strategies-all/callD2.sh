# 2026-11-24, call D2 (the machine of call D, whose bundle/ stays): before (HEAD 900f74e) and after
# for regeneration-sk and streaming-sk, fast math, and regeneration-2p-sk, every scene; then
# naive-mk in the thesis tables at 16 spp.
set -uo pipefail
cd "$(dirname "$0")"
gunzip -c ../bundleb/volpt-base.gz > bin/volpt-base; chmod +x bin/volpt-base
R=$OUT
OUT=/tmp/r/ab SKIP_CHECKS=1 SKIP_CAPS=1 TRIALS=5 T=90 STRATEGIES="naive-sk regeneration-sk" EXACT_STRATEGIES=" " \
  BASE_STRATEGIES="regeneration-sk streaming-sk" BASE_MATH=fast FAST_STRATEGIES="regeneration-sk streaming-sk regeneration-2p-sk" \
  bash strategies.sh > /tmp/r/ab.out 2>&1
cat /tmp/r/ab/bench.txt; grep FAIL /tmp/r/ab/summary.txt; cp /tmp/r/ab/bench.txt $R/ab-bench.txt
OUT=$R TRIALS=1 SPP=16 STRATEGIES="naive-sk naive-mk" bash thesis-tables.sh > /dev/null 2>&1
mv $R/thesis-tables.txt $R/thesis-tables-naive-16spp.txt; cat $R/thesis-tables-naive-16spp.txt
