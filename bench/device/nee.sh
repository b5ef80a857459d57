#!/usr/bin/env bash
# Next-event estimation against path tracing on the GPU, in efficiency 1 / (MSE x time)
# (docs/heterogeneous.md): `volpt converge --backend cuda --setting estimator=pt,nee` on smoke and
# envmap-cube (index-matched), regeneration-sk, exact and fast math, TIME seconds per setting,
# against a REFSPP GPU reference.
#   bash bundle/nee.sh   -> $OUT/nee.txt
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
TIME=${TIME:-1.5}
REFSPP=${REFSPP:-2048}
RES=${RES:-400x400}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/nee.XXXXXX")
"$VOLPT" scene generate scenes >/dev/null
SCENES=(
    "smoke:scenes/smoke/scene.xml:-Ddata=$PWD/data"
    "envmap-cube-index-matched:scenes/envmap-cube/index-matched.xml:"
)
{
    echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader) $RES, $TIME s per setting, reference $REFSPP spp"
    for entry in "${SCENES[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        # shellcheck disable=SC2086
        if timeout 200 "$VOLPT" converge "$file" $params --resolution "$RES" --backend cuda \
            --reference-spp "$REFSPP" --setting estimator=pt,nee --setting math=exact,fast \
            --time "$TIME" -o "$WORK/$name" >"$WORK/$name.log" 2>&1; then
            echo "== $name"
            cat "$WORK/$name/table.md"
        else
            echo "FAIL $name: $(tail -n 3 "$WORK/$name.log" | tr '\n' ' ')"
        fi
    done
} | tee "$OUT/nee.txt"
