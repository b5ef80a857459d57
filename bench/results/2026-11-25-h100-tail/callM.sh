# 2026-11-25, call M: the kernels of the tail change (exit distance, .ftz, drained warp), embedded in
# the binary: every check of strategies.sh (all strategies against the CPU on the seven scenes,
# naive-sk and naive-mk bit-identical; fast against exact as independent estimates; memcheck,
# racecheck), no benchmark.
set -uo pipefail
cd "$(dirname "$0")"
gunzip -f bin/volpt.gz; chmod +x bin/volpt
R=$OUT; OUT=/tmp/m SKIP_BENCH=1 SKIP_CAPS=1 timeout 540 bash strategies.sh > /dev/null 2>&1; echo "strategies.sh exit $?"
cp /tmp/m/summary.txt /tmp/m/device.txt $R/; grep -c PASS $R/summary.txt; grep -v PASS $R/summary.txt
