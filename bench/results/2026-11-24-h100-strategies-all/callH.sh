# 2026-11-25, call H: strategy.rs's shared start_path and Refill::ready (a refactor; the PTX differs
# by one branch's layout per refill): the kernels before (1-before.ptx, those of ce6661c) and after
# (2-after.ptx), fast math, through VOLPT_PTX with one binary, ab.sh's five scenes, median of 5.
set -uo pipefail
cd "$(dirname "$0")"
gunzip -f bin/volpt.gz ab/*.ptx.gz; chmod +x bin/volpt
TRIALS=5 STRATEGIES="regeneration-sk streaming-sk streaming-mk" bash ab.sh > /dev/null 2>&1
cat $OUT/ab.txt
