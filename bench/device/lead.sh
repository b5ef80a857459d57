#!/usr/bin/env bash
# The lead's batched device calls, from a folder laid out like `cargo xtask device-bundle`'s
# (bin/volpt or bin/volpt.xz, scenes/, data/, the bench/device scripts). Each session's calls and
# what they printed are in bench/results/<date>-<device>-session<N>/README.md.
#
#   bash dev/lead.sh checks    # main's final binary: every strategy and fast math against the
#                                   # CPU (short form), orthographic, materials, chromatic, and the
#                                   # helpers' device scripts named in EXTRA (lights, mesh, materials,
#                                   # print); keeps the binary in /tmp/volpt-lead for the next call,
#                                   # and a call without bin/volpt uses the kept one
#                                   # (CHECKS=none EXTRA="mesh.sh ..." runs the helpers' scripts only)
#   bash dev/lead.sh ab        # bin/volpt-before against the kept binary: AB picks ab-bin
#                                   # (grey box scenes, regeneration-sk and the defaults) and
#                                   # sparse-table (exact checks, tiles, the bricked and sparse A/B)
#   bash dev/lead.sh ptxas     # ptxas -v of every ab-ptxas/*.ptx, as built and under the
#                                   # defaults' 64-register cap: registers and spills per kernel
#   bash dev/lead.sh peers     # Mitsuba 3 on the kept binary: the wheel's parts carried in
#                                   # earlier calls (PEER_PARTS folders, unpacked into the site
#                                   # device.sh reuses), then MODE/SCENES of
#                                   # bench/peers/mitsuba3/device.sh
#   bash dev/lead.sh kernels   # the grey grid scenes' regression, bisected: the same binary
#                                   # (main at f8f3c96) runs each cut PTX of ab/*.ptx[.xz] (ab.sh,
#                                   # regeneration-sk, fast math, two rounds), and ptxas -v reports
#                                   # every PTX of ab/ and ab-ptxas/ (kernels of other host ABIs,
#                                   # compiled but not run)
#
# Each part writes under $OUT/<part>/; the summaries are gathered in $OUT/summary-<mode>.txt.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mode=${1:?usage: lead.sh checks|ab|kernels|ptxas|peers}
KEEP=/tmp/volpt-lead
mkdir -p "$KEEP/data"
mkdir -p "$OUT"
for f in bin/*.xz ab/*.xz ab-ptxas/*.xz; do [ -f "$f" ] && xz -d -f "$f"; done
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
    # A call without a binary uses the one an earlier call kept.
    if [ -f bin/volpt ]; then cp bin/volpt "$KEEP/volpt"; else mkdir -p bin && cp "$KEEP/volpt" bin/volpt; fi
    [ -d data ] && cp -r data/. "$KEEP/data/"
    for check in ${CHECKS:-strategies orthographic materials chromatic}; do
        case $check in
        strategies) part strategies 130 env TRIALS=3 T=30 PROBE_T=15 \
            SCENES_ONLY="^(homogeneous-cube-null|cgg-logo|smoke|bucky)$" EXACT_STRATEGIES="regeneration-sk" \
            FAST_STRATEGIES="regeneration-sk regeneration-warp-sk regeneration-block-sk streaming-sk" \
            CAPS="64" bash strategies.sh ;;
        materials) part materials 90 bash materials.sh ;;
        chromatic) part chromatic 100 env FILMS=${FILMS:-8} bash chromatic.sh ;;
        orthographic) part orthographic 90 bash orthographic.sh ;;
        esac
    done
    for extra in ${EXTRA:-}; do
        [ -f "$extra" ] && part "$(basename "$extra" .sh)" "${EXTRA_LIMIT:-150}" bash "$extra"
    done
    ;;
ab)
    cp "$KEEP/volpt" bin/volpt
    for ab in ${AB:-ab-bin sparse-table}; do
        case $ab in
        ab-bin) part ab-bin 200 env STRATEGIES="regeneration-sk defaults" TRIALS=3 bash ab-bin.sh ;;
        sparse-table) part sparse-table 200 bash sparse-table.sh ;;
        sparse-defaults) part sparse-defaults 200 env AB_ARGS= bash sparse-table.sh ;;
        esac
    done
    ;;
ptxas)
    ARCH=sm_$(nvidia-smi --query-gpu=compute_cap --format=csv,noheader | head -n 1 | tr -d '.')
    mkdir -p "$OUT/ptxas"
    for ptx in ab-ptxas/*.ptx; do
        name=$(basename "$ptx" .ptx)
        ptxas -arch="$ARCH" -v "$ptx" -o /dev/null >"$OUT/ptxas/ptxas-$name.txt" 2>&1 &
        ptxas -arch="$ARCH" -v -maxrregcount 64 "$ptx" -o /dev/null >"$OUT/ptxas/ptxas-$name-cap64.txt" 2>&1 &
        wait
    done
    for r in "$OUT"/ptxas/ptxas-*.txt; do
        awk -v p="$(basename "$r" .txt)" '/Compiling entry function/ {k=$0; sub(/.*function ./, "", k); sub(/. for .*/, "", k)}
            /bytes spill/ {s=$0; sub(/^ *ptxas info *: */, "", s)}
            /Used [0-9]+ registers/ {u=$0; sub(/.*Used/, "Used", u); print p, k ":", u, "|", s}' "$r"
    done >"$OUT/ptxas/registers.txt"
    ;;
peers)
    # The wheel travels in parts (the tree and the whole wheel pass the carry limit): each call
    # unpacks the parts it carries (PEER_PARTS: folders at the repository's root) into the site
    # device.sh reuses; PEER_RUN (device.sh's MODEs, e.g. "gpu print") then runs it on the kept
    # binary, each mode under PEER_LIMIT seconds (SCENES as device.sh reads it).
    root=$PWD; while [ ! -f "$root/bench/peers/mitsuba3/device.sh" ] && [ "$root" != / ]; do root=$(dirname "$root"); done
    PEER_SITE=${PEER_SITE:-/tmp/volpt-peer-site}
    mkdir -p "$PEER_SITE"
    for part in ${PEER_PARTS:-}; do
        for z in "$root/$part"/*.zip "$root/$part"/*.whl; do
            [ -f "$z" ] && python3 -m zipfile -e "$z" "$PEER_SITE" && echo "== unpacked $(basename "$z")" | tee -a "$summary"
        done
    done
    if [ -n "${PEER_RUN:-}" ]; then
        echo carried >"$PEER_SITE/.stamp"
        mkdir -p "$root/bundle/bin" && cp "$KEEP/volpt" "$root/bundle/bin/volpt"
        ln -sfn "$KEEP/data" "$root/bundle/data"
        ln -sfn "$root/scenes" "$root/bundle/scenes"
        for f in "$root"/bench/device/*.sh "$root"/bench/device/*.py; do ln -sfn "$f" "$root/bundle/"; done
        for mode in $PEER_RUN; do
            part "peers-$mode" "${PEER_LIMIT:-300}" env PEER_SITE="$PEER_SITE" MODE="$mode" bash "$root/bench/peers/mitsuba3/device.sh"
        done
    fi
    ;;
kernels)
    ARCH=sm_$(nvidia-smi --query-gpu=compute_cap --format=csv,noheader | head -n 1 | tr -d '.')
    mkdir -p "$OUT/ptxas"
    # ab.sh reports ab/*.ptx itself (in each round's folder); these are only compiled.
    for ptx in ab-ptxas/*.ptx; do
        [ -f "$ptx" ] && ptxas -arch="$ARCH" -v "$ptx" -o /dev/null >"$OUT/ptxas/ptxas-$(basename "$ptx" .ptx).txt" 2>&1 &
    done
    for round in 1 2; do
        part "ab-round$round" 240 env STRATEGIES=regeneration-sk TRIALS=5 bash ab.sh
    done
    wait
    # "ptx kernel: ptxas's Used line" for every report.
    for r in "$OUT"/ptxas/ptxas-*.txt "$OUT"/ab-round1/ptxas-*.txt; do
        [ -f "$r" ] && awk -v p="$(basename "$r" .txt)" '/Compiling entry function/ {k=$0; sub(/.*function ./, "", k); sub(/. for .*/, "", k)}
            /Used [0-9]+ registers/ {u=$0; sub(/.*Used/, "Used", u); print p, k ":", u}' "$r"
    done >"$OUT/ptxas/registers.txt"
    ;;
esac
for f in "$OUT"/*/summary.txt "$OUT"/peers-*/peers/device-summary.txt "$OUT"/peers-*/peers/results.md "$OUT"/ab-bin/ab-bin.txt "$OUT"/*/sparse-table.txt "$OUT"/ab-round*/ab.txt "$OUT"/ptxas/registers.txt; do
    [ -f "$f" ] && { echo "---- $f"; cat "$f"; } >>"$summary"
done
for d in "$OUT"/*/; do tail -n 3 "$d/stdout.txt" 2>/dev/null | sed "s|^|$(basename "$d"): |" >>"$summary"; done
cat "$summary"
