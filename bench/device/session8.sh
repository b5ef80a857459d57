#!/usr/bin/env bash
# Session 8's device calls (2026-11-28): the new surfaces' GPU checks and the grey scenes' A/B, from
# a folder laid out like `cargo xtask device-bundle`'s (bin/volpt or bin/volpt.xz, scenes/, data/,
# the bench/device scripts), in two calls back to back on one warm machine (the carry holds one
# stripped binary at a time):
#
#   bash dev/session8.sh checks   # quick-all (every strategy against the CPU, heterogeneous, out-of-core,
#                                 # auto), hostile-check, scanners, materials, chromatic, the README's
#                                 # chromatic images, the GPU test binaries in tests-bin/; keeps the
#                                 # binary in /tmp/session8 for the second call
#   bash dev/session8.sh ab       # bin/volpt-before (main at 564edf8) against the kept binary:
#                                 # ab-bin.sh on the grey box scenes, then sparse-table.sh (the
#                                 # two-level brick table: exact checks, tiles, bricked A/B)
#
# Each part writes under $OUT/<part>/; the summaries are gathered in $OUT/summary-<mode>.txt and the
# rest packed in $OUT/<mode>.tar.gz.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mode=${1:?usage: session8.sh checks|ab}
KEEP=/tmp/session8
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
    part quick-all 330 bash quick-all.sh
    part hostile 100 bash hostile-check.sh
    part scanners 60 bash scanners.sh
    [ -f materials.sh ] && part materials 240 bash materials.sh
    part chromatic 200 env FILMS=${FILMS:-8} bash chromatic.sh
    part readme-images 60 env ONLY="chromatic-cube chromatic-slab" bash readme-images.sh
    # The request tests, built on the development machine with the kernels embedded; they read the
    # repository's scenes through the path they were built at.
    if [ -d tests-bin ]; then
        mkdir -p /work && [ -e /work/main ] || ln -s "$(cd .. && pwd)" /work/main
        for t in tests-bin/*; do
            part "test-$(basename "$t")" 120 env VOLPT_REQUIRE_GPU=1 VOLPT_REQUIRE_PTX=1 "$t" --test-threads 1
        done
    fi
    ;;
ab)
    cp "$KEEP/volpt" bin/volpt
    part ab-bin 240 env STRATEGIES="regeneration-sk regeneration-block-sk" TRIALS=3 bash ab-bin.sh
    part sparse-table 300 bash sparse-table.sh
    ;;
esac
for f in "$OUT"/*/summary.txt "$OUT"/*/hostile.txt "$OUT"/ab-bin/ab-bin.txt "$OUT"/*/sparse-table.txt; do
    [ -f "$f" ] && { echo "---- $f"; cat "$f"; } >>"$summary"
done
for d in "$OUT"/*/; do tail -n 3 "$d/stdout.txt" 2>/dev/null | sed "s|^|$(basename "$d"): |" >>"$summary"; done
(cd "$OUT" && tar czf "$mode.tar.gz" --exclude='*.exr' --exclude='*.vfilm' --exclude='*.png' */ 2>/dev/null)
cat "$summary"
