# 2026-11-25, call E: regeneration-2p-sk after its two paths left local memory (named slots instead
# of an array): checks against the CPU on every scene, memcheck, benchmark beside regeneration-sk,
# and its rows of the thesis's tables.
set -uo pipefail
cd "$(dirname "$0")"
[ -f bin/volpt.gz ] && gunzip -f bin/volpt.gz; chmod +x bin/volpt
R=$OUT; mkdir -p /tmp/r
OUT=/tmp/r/checks2p STRATEGIES="naive-sk regeneration-2p-sk" SKIP_BENCH=1 T=90 bash strategies.sh > /tmp/r/checks2p.out 2>&1
timeout 90 compute-sanitizer --tool memcheck --error-exitcode 1 bin/volpt render scenes/cgg-logo/scene.xml -Dresolution=64 --spp 2 \
  --backend cuda --strategy regeneration-2p-sk -o /tmp/r/m.exr > /tmp/r/memcheck-2p.log 2>&1; echo "== memcheck regeneration-2p-sk exit $? $(tail -n 1 /tmp/r/memcheck-2p.log)" | tee -a /tmp/r/checks2p/summary.txt
grep -E "FAIL|failures|memcheck" /tmp/r/checks2p/summary.txt; echo "2p checks passed: $(grep -c '^== PASS' /tmp/r/checks2p/summary.txt)"
cp /tmp/r/checks2p/summary.txt $R/checks-2p-final.txt
OUT=/tmp/r/bench SKIP_CHECKS=1 SKIP_CAPS=1 TRIALS=5 T=90 STRATEGIES="naive-sk regeneration-sk" EXACT_STRATEGIES=" " \
  FAST_STRATEGIES="regeneration-sk regeneration-2p-sk" bash strategies.sh > /tmp/r/bench.out 2>&1
cat /tmp/r/bench/bench.txt; cp /tmp/r/bench/bench.txt $R/bench-2p-final.txt
cp /tmp/r/bench/ptxas-volpt_kernels_fast-summary.txt $R/ptxas-fast-final.txt 2>/dev/null
OUT=$R TRIALS=3 STRATEGIES="regeneration-sk regeneration-2p-sk" bash thesis-tables.sh > /dev/null 2>&1
mv $R/thesis-tables.txt $R/thesis-tables-2p-final.txt; cat $R/thesis-tables-2p-final.txt
