#!/usr/bin/env bash
# 2026-11-27 (session 6), one H100, the session's bundle (.dev/s7 as in call-ab.sh):
# 1. auto-check.sh: --strategy auto against every fixed choice it could make, five scenes;
# 2. ncu on one launch each of the index-matched cube and cgg-logo (regeneration-sk, the defaults,
#    400x400, 100 spp): instructions, lanes per instruction, issue, stall reasons;
# 3. the SASS of the index-matched cube's regeneration-sk kernel (ptxas of ab/2-after.ptx).
#   OUT=$OUT bash bench/results/2026-11-27-h100-session6/call-profile.sh
set -uo pipefail
B=$PWD/.dev/s7
[ -f "$B/bin/volpt.gz" ] && gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
[ -f "$B/ab/2-after.ptx.gz" ] && gunzip -f "$B"/ab/*.ptx.gz
cd "$B"
(ptxas -arch=sm_90 ab/2-after.ptx -o /tmp/after.cubin && cuobjdump -sass -fun regeneration_sk__homogeneous__index_matched__isotropic__constant /tmp/after.cubin > "$OUT/sass-cube.txt") > "$OUT/sass.log" 2>&1 &
OUT=/tmp/auto timeout 300 bash auto-check.sh > /dev/null 2>&1; cp /tmp/auto/auto-check.txt "$OUT/auto-check.txt"; cat "$OUT/auto-check.txt"
./bin/volpt scene generate scenes > /dev/null
for s in "cube-null:scenes/homogeneous-cube/scene.xml -Dboundary=null" "cgg-logo:scenes/cgg-logo/scene.xml"; do
    name=${s%%:*}; args=${s#*:}
    timeout 120 ncu --kernel-name regex:regeneration_sk --launch-count 1 \
        --section SpeedOfLight --section Occupancy --section LaunchStats --section WarpStateStats --section SchedulerStats --section InstructionStats \
        --metrics smsp__thread_inst_executed_per_inst_executed.ratio,smsp__inst_executed.sum,smsp__issue_active.avg.pct_of_peak_sustained_active \
        ./bin/volpt render $args --backend cuda --strategy regeneration-sk --spp 100 -o /tmp/p.exr > "$OUT/ncu-$name.txt" 2>&1
    grep -E "Duration|inst_executed|Issue Slots Busy|Warp Cycles Per Issued|Achieved Occupancy|Registers Per|ratio|Stall|No Eligible|Eligible Warps" "$OUT/ncu-$name.txt" | head -30
done
wait
wc -l "$OUT/sass-cube.txt"
