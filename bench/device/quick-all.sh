#!/usr/bin/env bash
# Every device check in one short call (about 6 minutes on an H100), for sessions with little device
# time: the strategies' selftest, a subset of strategies.sh (checks of every strategy and of fast math
# against the CPU, the benchmark before/after, register caps), heterogeneous.sh (naive-sk identity of
# the majorant-grid and NEE variants, global vs grid on smoke/bucky/ad/cgg-logo), out-of-core.sh in
# its QUICK form, and one `auto` calibration. Each part has its own time limit; what a part
# finished is packed even if it ran out of time.
#
#   bash bundle/quick-all.sh      # results under $OUT: summary.txt, bench.txt, *.tar.gz
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
WORK=${WORK:-$PWD/quick-work}
mkdir -p "$OUT" "$WORK"
# One `auto` cache for every command of the run.
export VOLPT_CACHE_DIR=$WORK/cache
say() { echo "== $*" | tee -a "$OUT/summary.txt"; }
part() { # part NAME LIMIT_S CMD...: runs CMD under a limit, keeps its output in WORK/NAME.log
    local name=$1 limit=$2; shift 2
    local t0; t0=$(date +%s)
    timeout "$limit" "$@" >"$WORK/$name.log" 2>&1
    say "$name: exit $? after $(($(date +%s) - t0)) s (limit $limit s)"
}

say "date $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader)"
part selftest 60 bin/volpt selftest
cat "$WORK/selftest.log" >>"$OUT/summary.txt"

mkdir -p "$WORK/strategies"
part strategies "${STRATEGIES_LIMIT:-170}" env OUT="$WORK/strategies" TRIALS=3 T=30 PROBE_T=15 \
    SCENES_ONLY="${SCENES_ONLY:-^(homogeneous-cube-null|cgg-logo|smoke|bucky)$}" \
    EXACT_STRATEGIES="regeneration-sk" \
    FAST_STRATEGIES="regeneration-sk regeneration-warp-sk regeneration-block-sk streaming-sk" \
    CAPS="64 96" bash strategies.sh
grep -v '^== PASS' "$WORK/strategies/summary.txt" >>"$OUT/summary.txt" 2>/dev/null
echo "== strategies: $(grep -c '^== PASS' "$WORK/strategies/summary.txt" 2>/dev/null) checks passed" >>"$OUT/summary.txt"
cp "$WORK/strategies/bench.txt" "$OUT/bench.txt" 2>/dev/null

mkdir -p "$WORK/heterogeneous"
part heterogeneous "${HETEROGENEOUS_LIMIT:-110}" env OUT="$WORK/heterogeneous" TRIALS=2 RESOLUTIONS="32" \
    bash heterogeneous.sh
cat "$WORK/heterogeneous/summary.txt" >>"$OUT/summary.txt" 2>/dev/null
cp "$WORK/heterogeneous/summary.csv" "$OUT/heterogeneous.csv" 2>/dev/null

mkdir -p "$WORK/ooc"
part out-of-core "${OOC_LIMIT:-90}" env OUT="$WORK/ooc" WORK="$WORK/ooc-work" QUICK=1 MID_RES=256 TRIALS=2 \
    bash out-of-core.sh
cat "$WORK/ooc/summary.txt" >>"$OUT/summary.txt" 2>/dev/null

part auto 60 bin/volpt bench scenes/cgg-logo/scene.xml --backend cuda --trials 2
grep -A12 '^auto:' "$WORK/auto.log" >>"$OUT/summary.txt"
tail -n 1 "$WORK/auto.log" >>"$OUT/summary.txt"

# Everything else, small files only, in one archive.
(cd "$WORK" && find . -name '*.exr' -o -name '*.png' -o -name '*.vol' -o -name '*.raw' -o -name '*.ptx' \
    | xargs rm -f; tar czf "$OUT/details.tar.gz" --exclude=ooc-work --exclude=cache . 2>/dev/null)
say "done"
