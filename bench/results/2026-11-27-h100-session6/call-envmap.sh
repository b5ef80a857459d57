#!/usr/bin/env bash
# 2026-11-27 (session 6), one H100, the final bundle (.dev/s8): envmap-cube with path tracing and
# with next-event estimation at the rough boundary (--estimator pt|nee), the defaults otherwise:
# time (volpt bench, median of 5) and one ncu launch each (instructions, lanes, stall reasons per
# issued instruction), to see where nee's cost goes.
#   OUT=$OUT bash bench/results/2026-11-27-h100-session6/call-envmap.sh
set -uo pipefail
B=$PWD/.dev/s8
[ -f "$B/bin/volpt.gz" ] && gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
cd "$B"
./bin/volpt scene generate scenes > /dev/null
M=smsp__inst_executed.sum,smsp__thread_inst_executed_per_inst_executed.ratio,gpu__time_duration.sum,smsp__issue_active.avg.pct_of_peak_sustained_active
for s in long_scoreboard short_scoreboard wait math_pipe_throttle no_instruction branch_resolving barrier lg_throttle mio_throttle tex_throttle not_selected selected dispatch_stall membar sleeping drain imc_miss; do
    M=$M,smsp__average_warps_issue_stalled_${s}_per_issue_active.ratio
done
for e in pt nee; do
    ./bin/volpt bench scenes/envmap-cube/scene.xml --backend cuda --estimator $e --trials 5 --json 2>/dev/null \
      | python3 -c "import json,sys; r=json.load(sys.stdin); print(f\"$e: {r['time_median_s']*1e3:.2f} ms, {r['segments']/r['paths']:.2f} segments/path\")"
    timeout 120 ncu --kernel-name regex:regeneration_sk --launch-count 1 --metrics $M \
        ./bin/volpt render scenes/envmap-cube/scene.xml --backend cuda --estimator $e -o /tmp/e.exr > "$OUT/ncu-envmap-$e.txt" 2>&1
    grep -E "inst_executed|ratio|duration|pct" "$OUT/ncu-envmap-$e.txt" | awk '{print "   ", $1, $(NF)}'
done | tee "$OUT/envmap.txt"
