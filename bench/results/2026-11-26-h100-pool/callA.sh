# 2026-11-26, call A: branch `pool` (strategy.rs as one persistent loop over a path pool; naive-mk and
# streaming-mk sharing one kernel function) on the device, from its bundle (`cargo xtask
# device-bundle`, bin/volpt gzipped, the full-module PTX copies left out; ab/1-before.ptx and
# ab/2-after.ptx: the fast-math kernels of main b2d71e4 and of the branch for the seven persistent
# strategies on ab.sh's five scenes, cut with ptx_cut.py).
# 1. strategies.sh's checks, no benchmark: every strategy against the CPU on the seven scenes
#    (naive-sk and naive-mk bit-identical, the others within 1e-6), fast against exact math,
#    memcheck of every strategy but the naive ones, racecheck of the three that exchange paths
#    through shared memory;
# 2. ab.sh: the persistent strategies' kernels before and after through VOLPT_PTX with one binary
#    (fast math, 100 spp, bucky 300, median of 3), and ptxas -v of both cut modules.
set -uo pipefail
cd "$(dirname "$0")"
gunzip -f bin/volpt.gz ab/*.ptx.gz; chmod +x bin/volpt
R=$OUT; mkdir -p /tmp/r
OUT=/tmp/r/checks SKIP_BENCH=1 T=60 RACECHECK_T=150 bash strategies.sh > /tmp/r/checks.out 2>&1
grep -E "FAIL|failures" /tmp/r/checks/summary.txt; echo "checks passed: $(grep -c '^== PASS' /tmp/r/checks/summary.txt)"
cp /tmp/r/checks/summary.txt $R/checks-summary.txt
OUT=/tmp/r/ab TRIALS=3 STRATEGIES="regeneration-sk regeneration-warp-sk regeneration-block-sk streaming-sk regeneration-2p-sk streaming-sorted-sk sorting-sk" bash ab.sh > /dev/null 2>&1
cp /tmp/r/ab/ab.txt $R/ab.txt
for f in /tmp/r/ab/ptxas-*.txt; do
  python3 - "$f" > $R/$(basename "$f" .txt)-summary.txt <<'PY'
import re, sys
text = open(sys.argv[1]).read()
for m in re.finditer(r"Compiling entry function '(\w+)'.*?Used (\d+) registers[^\n]*", text, re.S):
    block = text[m.start():m.end()]
    stack = re.search(r"(\d+) bytes stack frame", block)
    spill = re.search(r"(\d+) bytes spill stores", block)
    print(f"{m.group(1):<90} {m.group(2):>4} regs  stack {stack.group(1) if stack else '?':>4}  spills {spill.group(1) if spill else '?'}")
PY
done
cat $R/ab.txt
