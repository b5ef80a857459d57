# 2026-11-24, call D: regeneration-2p-sk checked against the CPU on every scene (+ memcheck), the
# multi-kernel launches' iteration counts, then thesis-tables.sh with every strategy.
set -uo pipefail
cd "$(dirname "$0")"
[ -f bin/volpt.gz ] && gunzip -f bin/volpt.gz; chmod +x bin/volpt
R=$OUT; mkdir -p /tmp/r
OUT=/tmp/r/checks2p STRATEGIES="naive-sk regeneration-2p-sk" SKIP_BENCH=1 T=90 bash strategies.sh > /tmp/r/checks2p.out 2>&1
timeout 90 compute-sanitizer --tool memcheck --error-exitcode 1 bin/volpt render scenes/cgg-logo/scene.xml -Dresolution=64 --spp 2 \
  --backend cuda --strategy regeneration-2p-sk -o /tmp/r/m.exr > /tmp/r/memcheck-2p.log 2>&1; echo "== memcheck regeneration-2p-sk exit $? $(tail -n 1 /tmp/r/memcheck-2p.log)" | tee -a /tmp/r/checks2p/summary.txt
grep -E "FAIL|failures|memcheck" /tmp/r/checks2p/summary.txt; echo "2p checks passed: $(grep -c '^== PASS' /tmp/r/checks2p/summary.txt)"
cp /tmp/r/checks2p/summary.txt $R/checks-2p.txt
for s in naive-mk streaming-mk; do
  RUST_LOG=volpt_cuda=debug bin/volpt render scenes/cgg-logo/scene.xml --spp 3 --backend cuda --strategy $s -o /tmp/r/n.exr 2>&1 | grep -i "wavefront" | sed "s/^/$s /"
done | tee $R/wavefront-iterations.txt
OUT=$R TRIALS=3 STRATEGIES="naive-sk regeneration-sk regeneration-warp-sk regeneration-block-sk regeneration-2p-sk streaming-sk streaming-sorted-sk sorting-sk streaming-mk" bash thesis-tables.sh > /dev/null 2>&1
mv $R/thesis-tables.txt $R/thesis-tables-all.txt; cat $R/thesis-tables-all.txt
