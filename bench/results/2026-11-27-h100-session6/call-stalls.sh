#!/usr/bin/env bash
# 2026-11-27 (session 6), one H100, the final bundle (.dev/s8): one ncu launch of regeneration-sk
# with the defaults on four more scenes: instructions, lanes and each stall reason per issued
# instruction (as call-envmap.sh), to see which scenes wait on instruction fetch ("no_instruction").
#   OUT=$OUT bash bench/results/2026-11-27-h100-session6/call-stalls.sh
set -uo pipefail
B=$PWD/.dev/s8
[ -f "$B/bin/volpt.gz" ] && gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
cd "$B"
./bin/volpt scene generate scenes > /dev/null
M=smsp__inst_executed.sum,smsp__thread_inst_executed_per_inst_executed.ratio,gpu__time_duration.sum,smsp__issue_active.avg.pct_of_peak_sustained_active
for s in long_scoreboard short_scoreboard wait math_pipe_throttle no_instruction branch_resolving lg_throttle mio_throttle not_selected selected dispatch_stall; do
    M=$M,smsp__average_warps_issue_stalled_${s}_per_issue_active.ratio
done
for e in "cube-null|scenes/homogeneous-cube/scene.xml -Dboundary=null" "cube|scenes/homogeneous-cube/scene.xml" "cgg-logo|scenes/cgg-logo/scene.xml" "bucky|scenes/bucky/scene.toml -Ddata=$PWD/data"; do
    name=${e%%|*}; args=${e#*|}
    echo "$name"
    timeout 120 ncu --kernel-name regex:regeneration_sk --launch-count 1 --metrics $M \
        ./bin/volpt render $args --backend cuda --spp 100 -o /tmp/e.exr > "$OUT/ncu-stalls-$name.txt" 2>&1
    grep -E "inst_executed|ratio|duration|pct" "$OUT/ncu-stalls-$name.txt" | awk '{print "   ", $1, $(NF)}'
done | tee "$OUT/stalls.txt"
