#!/usr/bin/env bash
# Session 9's device calls (2026-11-28/29), from a folder laid out like `cargo xtask device-bundle`'s
# (bin/volpt or bin/volpt.xz, scenes/, data/, the bench/device scripts), in two calls back to back on
# one warm machine (the carry holds one stripped binary at a time). The session had ~13 minutes of
# device time, so each part is the short form of its script:
#
#   bash dev/session9.sh checks   # quick-all (every strategy against the CPU, heterogeneous,
#                                 # out-of-core, auto), materials, chromatic (8 films), the helpers'
#                                 # new checks where their scripts are present; keeps the binary in
#                                 # /tmp/session9 for the second call
#   bash dev/session9.sh ab       # bin/volpt-before (main at 564edf8, before the two-level brick
#                                 # table) against the kept binary: ab-bin.sh on the grey box scenes,
#                                 # then sparse-table.sh (exact checks, tiles, the bricked and sparse A/B)
#
# Each part writes under $OUT/<part>/; the summaries are gathered in $OUT/summary-<mode>.txt.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mode=${1:?usage: session9.sh checks|ab}
KEEP=/tmp/session9
mkdir -p "$OUT" "$KEEP"
for f in bin/*.xz; do [ -f "$f" ] && xz -d -f "$f"; done
chmod +x bin/* 2>/dev/null
summary=$OUT/summary-$mode.txt
part() { # part NAME LIMIT_S CMD...: CMD with OUT=$OUT/NAME under a time limit
    local name=$1 limit=$2; shift 2
    local t0; t0=$(date +%s)
    mkdir -p "$OUT/$name"
    OUT=$OUT/$name timeout "$limit" "$@" >"$OUT/$name/stdout.txt" 2>&1
    echo "== $name: exit $? after $(($(date +%s) - t0)) s (limit $limit s)" | tee -a "$summary"
}
echo "== $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -n 1)" | tee "$summary"
case $mode in
checks)
    cp bin/volpt "$KEEP/volpt"
    # CHECKS picks the parts (all by default); EXTRA adds scripts of this folder.
    for check in ${CHECKS:-quick-all materials chromatic}; do
        case $check in
        quick-all) part quick-all 240 env STRATEGIES_LIMIT=120 bash quick-all.sh ;;
        # quick-all's strategy checks alone (every strategy and fast math against the CPU).
        strategies) part strategies 130 env TRIALS=3 T=30 PROBE_T=15 \
            SCENES_ONLY="^(homogeneous-cube-null|cgg-logo|smoke|bucky)$" EXACT_STRATEGIES="regeneration-sk" \
            FAST_STRATEGIES="regeneration-sk regeneration-warp-sk regeneration-block-sk streaming-sk" \
            CAPS="64" bash strategies.sh ;;
        materials) part materials 90 bash materials.sh ;;
        chromatic) part chromatic 100 env FILMS=${FILMS:-8} bash chromatic.sh ;;
        orthographic) part orthographic 90 bash orthographic.sh ;;
        materials-cost) part materials-cost 120 bash materials-cost.sh ;;
        # From the repository's root (the script reads scenes/example there).
        facade-typed) part facade-typed 60 env VOLPT="$PWD/bin/volpt" bash ../bench/device/facade-typed.sh ;;
        esac
    done
    for extra in ${EXTRA:-}; do
        [ -f "$extra" ] && part "$(basename "$extra" .sh)" 120 bash "$extra"
    done
    ;;
ab)
    cp "$KEEP/volpt" bin/volpt
    # AB picks the parts; BEFORE is bin/volpt-before (the carried binary).
    for ab in ${AB:-ab-bin sparse-table}; do
        case $ab in
        ab-bin) part ab-bin 120 env STRATEGIES="regeneration-sk" TRIALS=3 bash ab-bin.sh ;;
        sparse-table) part sparse-table 150 bash sparse-table.sh ;;
        materials-cost) cp bin/volpt-before bin/volpt-base
            part materials-cost 120 env SPP=64 bash materials-cost.sh ;;
        esac
    done
    ;;
esac
for f in "$OUT"/*/summary.txt "$OUT"/ab-bin/ab-bin.txt "$OUT"/*/sparse-table.txt "$OUT"/*/cost.txt; do
    [ -f "$f" ] && { echo "---- $f"; cat "$f"; } >>"$summary"
done
for d in "$OUT"/*/; do tail -n 3 "$d/stdout.txt" 2>/dev/null | sed "s|^|$(basename "$d"): |" >>"$summary"; done
cat "$summary"
