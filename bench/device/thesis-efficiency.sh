#!/usr/bin/env bash
# Efficiency, 1 / (MSE x time), of the thesis's renderer and of volpt on the thesis's scenes, each
# with each of its roulettes (issue 9: "more efficient with each side's best roulette").
#
# The thesis binary fixes its random seed, so its variance cannot come from repeated renders.
# Instead each side's SPP image is compared with its own REFSPP image of the same estimator: the
# mean squared difference over pixels and channels is the SPP image's variance plus the
# reference's, so it is divided by 1 + SPP/REFSPP. Comparing each side with its own reference also
# keeps the 0.7% difference of the two renderers' image means (thesis.sh) out of the error.
# Time: the mean of TRIALS timed renders at SPP after a warm-up (the thesis: its host clock around
# render(); volpt: `volpt bench`).
#   bash bundle/thesis-efficiency.sh   -> $OUT/thesis-efficiency.txt
# Needs the peer in bundle/thesis (see thesis.sh). Knobs: SPP (100), REFSPP (4096), TRIALS (5),
# RES (400), SCENES ("cgg_logo ad"), LOOKUP (texture), MATH (fast), STRATEGY (empty: no --strategy,
# volpt's default for a render this short, `volpt::auto::DEFAULT`).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
PEER=$PWD/thesis
SPP=${SPP:-100}
REFSPP=${REFSPP:-4096}
TRIALS=${TRIALS:-5}
RES=${RES:-400}
SCENES=${SCENES:-cgg_logo ad}
LOOKUP=${LOOKUP:-texture}
MATH=${MATH:-fast}
STRATEGY=${STRATEGY:-}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/thesis-efficiency.XXXXXX")
# An empty auto cache: without --strategy, volpt's choice is then its default, not one cached earlier.
export VOLPT_CACHE_DIR=$WORK/cache
export RUST_BACKTRACE=0 RUST_LIB_BACKTRACE=0
[ -d "$PEER/lib" ] && export LD_LIBRARY_PATH=$PEER/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
PEER_BIN=$PEER/bin
if [ ! -d "$PEER_BIN" ]; then
    PEER_BIN=$WORK/bin
    python3 -c 'import sys, tarfile
safe = {"filter": "data"} if hasattr(tarfile, "data_filter") else {}
tarfile.open(sys.argv[1]).extractall(sys.argv[2], **safe)' "$PEER/bin.tar.xz" "$WORK" \
        || { echo "FAIL unpacking $PEER/bin.tar.xz"; exit 1; }
fi
python3 "$PEER/gen_scenes.py" "$WORK/scenes" >"$WORK/gen.log" 2>&1 \
    || { echo "FAIL gen_scenes: $(tail -n 2 "$WORK/gen.log")"; exit 1; }
# The thesis's XML files name the medium's box as data/bounds.obj, which the thesis's loader does
# not read and the peer's gen_scenes.py does not write; volpt reads it: the box of each medium.
python3 - "$WORK/scenes" <<'PY' || { echo "FAIL writing bounds.obj"; exit 1; }
import itertools, os, sys
boxes = {"cgg_logo": ((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5)), "ad": ((-1.6, -1.6, -0.5), (1.6, 1.6, 0.5))}
faces = [(1, 2, 4), (1, 4, 3), (5, 7, 8), (5, 8, 6), (1, 5, 6), (1, 6, 2),
         (3, 4, 8), (3, 8, 7), (1, 3, 7), (1, 7, 5), (2, 6, 8), (2, 8, 4)]
for scene, (lo, hi) in boxes.items():
    path = os.path.join(sys.argv[1], scene, "data", "bounds.obj")
    if os.path.exists(path) or not os.path.isdir(os.path.join(sys.argv[1], scene)):
        continue
    os.makedirs(os.path.dirname(path), exist_ok=True)
    corners = itertools.product(*zip(lo, hi))
    with open(path, "w") as f:
        f.writelines(f"v {x} {y} {z}\n" for x, y, z in corners)
        f.writelines(f"f {a} {b} {c}\n" for a, b, c in faces)
PY

# row SCENE ENGINE SETTING TIME MSE: one line of the table, with the efficiency.
row() {
    python3 -c 'import sys
scene, engine, setting, t, mse, spp, ref = sys.argv[1:]
t, mse = float(t), float(mse) / (1 + float(spp) / float(ref))
print(f"| {scene} | {engine} | {setting} | {t:.4f} | {mse:.4e} | {1 / (mse * t):.4e} |")' \
        "$1" "$2" "$3" "$4" "$5" "$SPP" "$REFSPP"
}

thesis_side() { # thesis_side SCENE SETTING BINARY
    local scene=$1 setting=$2 bin=$PEER_BIN/cvr_$3 xml=$WORK/scenes/$1/volpath_bsdf.xml t mse
    [ -x "$bin" ] || { echo "SKIP thesis $scene $setting: no $bin"; return; }
    local args=(--interactive false -a cudaVolPath -k regenerationSK -r "$RES" "$RES")
    timeout 120 "$bin" "$xml" "${args[@]}" -i "$SPP" --trials $((TRIALS + 1)) -o "$WORK/t-$scene-$setting" \
        >"$WORK/t.log" 2>&1 || { echo "FAIL thesis $scene $setting: $(tail -n 2 "$WORK/t.log" | tr '\n' ' ')"; return; }
    t=$(grep -o -m 1 -E "wall mean time [0-9.]+" "$WORK/t.log" | grep -o -E "[0-9.]+$")
    timeout 300 "$bin" "$xml" "${args[@]}" -i "$REFSPP" --trials 1 -o "$WORK/t-$scene-$setting-ref" \
        >"$WORK/t.log" 2>&1 || { echo "FAIL thesis $scene $setting reference"; return; }
    mse=$(python3 rgbe.py "$WORK/t-$scene-$setting.hdr" "$WORK/t-$scene-$setting-ref.hdr" | grep -o -E "mse [0-9.e+-]+" | cut -d' ' -f2)
    row "$scene" thesis "$setting" "$t" "$mse"
}

volpt_side() { # volpt_side SCENE SETTING VOLPT-ARGS...
    local scene=$1 setting=$2 xml=$WORK/scenes/$1/volpath_bsdf.xml t mse
    shift 2
    local args=(--backend cuda ${STRATEGY:+--strategy "$STRATEGY"} --math "$MATH" --lookup "$LOOKUP" --resolution "${RES}x$RES" "$@")
    timeout 120 "$VOLPT" bench "$xml" "${args[@]}" --spp "$SPP" --trials "$TRIALS" --json >"$WORK/b.json" 2>"$WORK/v.log" \
        || { echo "FAIL volpt $scene $setting: $(grep -m 1 -E "Error|error" "$WORK/v.log")"; return; }
    t=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["time_mean_s"])' "$WORK/b.json")
    "$VOLPT" render "$xml" "${args[@]}" --spp "$SPP" --seed 1 -o "$WORK/v.exr" >/dev/null 2>"$WORK/v.log" \
        && "$VOLPT" render "$xml" "${args[@]}" --spp "$REFSPP" --seed 2 -o "$WORK/v-ref.exr" >/dev/null 2>"$WORK/v.log" \
        || { echo "FAIL volpt $scene $setting render: $(grep -m 1 -E "Error|error" "$WORK/v.log")"; return; }
    mse=$("$VOLPT" compare "$WORK/v.exr" "$WORK/v-ref.exr" | grep -o -E "mse [0-9.e+-]+" | cut -d' ' -f2)
    row "$scene" "volpt ${STRATEGY:-default} $MATH $LOOKUP" "$setting" "$t" "$mse"
}

{
    echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader) ${RES}x$RES, $SPP spp against each side's own $REFSPP-spp image; time: mean of $TRIALS"
    echo "| scene | engine | roulette | time s | MSE (reference noise removed) | efficiency 1/(MSE s) |"
    echo "|---|---|---|---:|---:|---:|"
    for scene in $SCENES; do
        thesis_side "$scene" none norr_stats
        thesis_side "$scene" "thesis: min(1, max T) from the first bounce" thread_stats
        volpt_side "$scene" none --rr-depth -1
        volpt_side "$scene" "thesis: min(1, max T) from the first bounce" --roulette throughput --rr-depth 0
        volpt_side "$scene" "mitsuba from depth 5" --roulette mitsuba --rr-depth 5
    done
} 2>&1 | tee "$OUT/thesis-efficiency.txt"
