#!/usr/bin/env bash
# 2026-11-27T00:32Z, one H100, the bundle of call.sh (.dev/s4) on the same warm machine: envmap-cube
# (its own 320x320, 100 spp) with path tracing and with next-event estimation at the rough boundary,
# under four strategies, `volpt bench` median of 3; then which strategy `auto` chose for nee.
# Output (medians, from the call's log): estimator.txt.
B=.dev/s4; [ -f $B/bin/volpt.gz ] && gunzip -f $B/bin/volpt.gz; chmod +x $B/bin/volpt; cd $B
S=scenes/envmap-cube/scene.xml
for est in pt nee; do for st in auto regeneration-sk naive-sk streaming-sk; do
    echo "== $est $st"
    ./bin/volpt bench $S --backend cuda --estimator $est --strategy $st --spp 100 --trials 3 --json 2>/dev/null \
        | python3 -c "import json,sys; r=json.load(sys.stdin); print({k: r[k] for k in r if k in ('time_median_s','segments_per_s','paths_per_s','strategy')})"
done; done
RUST_LOG=volpt=debug ./bin/volpt render $S --backend cuda --estimator nee --spp 100 -o /tmp/x.exr 2>&1 | grep -i -E "auto|strategy|kernel|launch" | head -8
