#!/usr/bin/env bash
# The thesis's strategy tables (4.1, 4.3, 6.1-6.3: rays/s and time per method on cgg-logo, ad,
# smoke and bucky) redone with volpt's strategies on the lent GPU (docs/strategies.md, "Against
# the thesis"). Each scene at 400x400, 100 spp (bucky 300), `volpt bench`, median of TRIALS
# after a warm-up, with the thesis's roulette (min(1, max T) from the first bounce, on in its
# measurements), in two configurations: exact arithmetic with trilinear lookups (volpt's default)
# and fast arithmetic with texture lookups (the thesis read its grids through textures).
#   bash bundle/thesis-tables.sh   -> $OUT/thesis-tables.txt
# Knobs: SPP (100; bucky 3x), TRIALS (5), STRATEGIES, CONFIGS ("exact:trilinear fast:texture").
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
SPP=${SPP:-100}
TRIALS=${TRIALS:-5}
STRATEGIES=${STRATEGIES:-naive-sk regeneration-sk regeneration-warp-sk regeneration-block-sk regeneration-2p-sk streaming-sk streaming-sorted-sk sorting-sk naive-mk streaming-mk}
CONFIGS=${CONFIGS:-exact:trilinear fast:texture}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/thesis-tables.XXXXXX")
export RUST_BACKTRACE=0 RUST_LIB_BACKTRACE=0
"$VOLPT" scene generate scenes >/dev/null
SCENES=(
    "cgg-logo:scenes/cgg-logo/scene.xml:"
    "ad:scenes/ad/scene.xml:"
    "smoke:scenes/smoke/scene.xml:-Ddata=$PWD/data"
    "bucky:scenes/bucky/scene.toml:-Ddata=$PWD/data"
)
{
    echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv,noheader); 400x400, $SPP spp (bucky 3x), the thesis's roulette, median of $TRIALS"
    echo "| scene | strategy | math | lookup | time s | G seg/s | M paths/s | segments/path |"
    echo "|---|---|---|---|---:|---:|---:|---:|"
    for entry in "${SCENES[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        spp=$SPP
        [ "$name" = bucky ] && spp=$((3 * SPP))
        for config in $CONFIGS; do
            IFS=: read -r math lookup <<<"$config"
            for strategy in $STRATEGIES; do
                # shellcheck disable=SC2086
                if timeout 120 "$VOLPT" bench "$file" $params --spp "$spp" --backend cuda --strategy "$strategy" \
                    --math "$math" --lookup "$lookup" --roulette throughput --rr-depth 0 --trials "$TRIALS" \
                    --json >"$WORK/b.json" 2>"$WORK/b.log"; then
                    python3 -c 'import json, sys
r = json.load(open(sys.argv[1]))
t, seg, paths = r["time_median_s"], r["segments_per_s"] / 1e9, r["paths_per_s"] / 1e6
per_path = r["segments"] / r["paths"]
print(f"| {sys.argv[2]} | {sys.argv[3]} | {sys.argv[4]} | {sys.argv[5]} | {t:.4f} | {seg:.3f} | {paths:.2f} | {per_path:.2f} |")' \
                        "$WORK/b.json" "$name" "$strategy" "$math" "$lookup"
                else
                    echo "FAIL $name $strategy $math $lookup: $(grep -m 1 -E "Error|error" "$WORK/b.log")"
                fi
            done
        done
    done
} 2>&1 | tee "$OUT/thesis-tables.txt"
