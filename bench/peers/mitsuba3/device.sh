#!/usr/bin/env bash
# Mitsuba 3 peer comparison on the device machine (no internet). Run from the repository root with
# `bundle/` (volpt's device bundle: bin/volpt, scenes/, data/) and `bundle-peer/` (the slimmed
# mitsuba + drjit cp312 wheels, see docs/peers.md) carried:
#
#   bash bench/peers/mitsuba3/device.sh            # GPU (cuda_ad_rgb vs volpt --backend cuda), then CPU
#   MODE=gpu bash bench/peers/mitsuba3/device.sh   # only the GPU rows; MODE=cpu only the CPU rows
#   MODE=print bash bench/peers/mitsuba3/device.sh # issue 40: compensated prints against naive ones,
#                                                  # rendered by Mitsuba 3 (bundle/print.sh's records;
#                                                  # it runs first if they are missing), print.py;
#                                                  # PRINT_STEPS and PRINT_TARGETS pass to print.sh
#                                                  # (PRINT_STEPS=3 PRINT_TARGETS=lines: the fine
#                                                  # target alone), PRINT_SPP to print.py
#
# Settings: GPU_RES/GPU_SPP (default 400/100, the thesis settings), CPU_RES/CPU_SPP (default 100/64:
# Mitsuba's LLVM backend is slow on these dense scenes), SCENES (names, default the seven grey
# scenes; chromatic-cube and chromatic-slab name scenes/chromatic's media, which Mitsuba renders with
# `volpathmis`; sun-slab, spot-fog and spot-fog-chromatic name scenes/lights' directional and spot
# emitters: `SCENES="sun-slab spot-fog spot-fog-chromatic"`; mesh-sphere-smooth and mesh-torus-rough
# name scenes/mesh-peers' triangle-mesh boundaries, issue 39: a smooth dielectric sphere mesh and a
# rough dielectric torus holding a density grid: `MODE=cpu SCENES="mesh-sphere-smooth
# mesh-torus-rough"`, and on the GPU the same (`MODE=gpu`; the torus's environment map has mesh
# kernels since session 13); mesh-sphere-shaded is the sphere with smooth vertex normals, which
# volpt renders on the CPU only (`MODE=cpu`, or compare.py `--backend cpu --variant cuda_ad_rgb`).
# Everything lands under $OUT/peers: results.md (one Markdown row per scene and device), <name>.json,
# the EXR images, the Mitsuba 3 XML each scene was rendered from, and the logs.
#
# The wheels are not pip-installed: a wheel is a zip, so they are unpacked into $PEER_SITE (default
# /tmp/volpt-peer-site, reused while the machine stays warm) and put on PYTHONPATH. That needs only
# python3.12 (the wheels are cp312), not pip or venv. If bundle-peer/ was not carried but
# $PEER_SITE is already populated (an earlier call on the same warm machine), that is used, so the
# two folders can also be carried in two calls if they do not fit in one.
set -uo pipefail
cd "$(dirname "$0")/../../.."
ROOT=$PWD
OUT=${OUT:-$ROOT/out}
RES_DIR=$OUT/peers
mkdir -p "$RES_DIR"
MODE=${MODE:-all}
PEER_SITE=${PEER_SITE:-/tmp/volpt-peer-site}
GPU_RES=${GPU_RES:-400}; GPU_SPP=${GPU_SPP:-100}
CPU_RES=${CPU_RES:-100}; CPU_SPP=${CPU_SPP:-64}
SCENES=${SCENES:-"homogeneous-cube homogeneous-cube-null cgg-logo ad smoke bucky envmap-cube"}
log() { echo "== $*" | tee -a "$RES_DIR/device-summary.txt"; }

# --- python 3.12 --------------------------------------------------------------------------------
PY=""
for cand in python3.12 python3; do
    if command -v "$cand" >/dev/null && "$cand" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 12))'; then
        PY=$(command -v "$cand"); break
    fi
done
if [ -z "$PY" ]; then
    log "FAIL no python3.12 on this machine (found: $(command -v python3 || echo none) $(python3 --version 2>&1));"
    log "     the carried wheels are cp312: download the matching cp3XY wheels with pip download (docs/peers.md)"
    exit 2
fi
log "python $PY ($("$PY" --version 2>&1))"

# --- unpack the wheels --------------------------------------------------------------------------
if compgen -G "bundle-peer/mitsuba-*-cp312-*.whl" >/dev/null; then
    stamp=$(ls -l bundle-peer/*.whl | md5sum | cut -c1-12)
    if [ "$(cat "$PEER_SITE/.stamp" 2>/dev/null)" != "$stamp" ]; then
        rm -rf "$PEER_SITE" && mkdir -p "$PEER_SITE"
        for whl in bundle-peer/*.whl; do "$PY" -m zipfile -e "$whl" "$PEER_SITE" || { log "FAIL unpack $whl"; exit 2; }; done
        echo "$stamp" >"$PEER_SITE/.stamp"
        log "unpacked $(ls bundle-peer/*.whl | xargs -n1 basename | tr '\n' ' ') into $PEER_SITE"
    fi
elif [ -f "$PEER_SITE/.stamp" ]; then
    log "bundle-peer/ not carried; using the wheels already unpacked in $PEER_SITE"
else
    log "FAIL neither bundle-peer/*.whl nor an unpacked $PEER_SITE: carry bundle-peer"
    exit 2
fi
export PYTHONPATH=$PEER_SITE${PYTHONPATH:+:$PYTHONPATH}
"$PY" -c 'import mitsuba, drjit; print("mitsuba", mitsuba.__version__, "drjit", drjit.__version__, mitsuba.variants())' \
    2>&1 | tee -a "$RES_DIR/device-summary.txt"
"$PY" -c 'import numpy' 2>/dev/null && log "numpy available" || log "no numpy: statistics in plain Python (same results, slower)"

# --- volpt bundle -------------------------------------------------------------------------------
VOLPT=$ROOT/bundle/bin/volpt
if [ ! -x "$VOLPT" ]; then
    log "bundle/bin/volpt missing: carry bundle (wheels are unpacked; run again with bundle carried)"
    exit 0
fi
"$VOLPT" scene generate bundle/scenes >"$RES_DIR/generate.log" 2>&1 || log "FAIL volpt scene generate"
DATA=$ROOT/bundle/data
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null | tee "$RES_DIR/device.txt"
nproc >>"$RES_DIR/device.txt"
GPU_NAME=$(nvidia-smi --query-gpu=name --format=csv,noheader 2>/dev/null | head -n 1)
CPU_DESC="device CPU ($(nproc) cores)"

scene_args() { # name -> file and -D parameters
    case $1 in
        homogeneous-cube) echo "bundle/scenes/homogeneous-cube/scene.xml" ;;
        homogeneous-cube-null) echo "bundle/scenes/homogeneous-cube/scene.xml -D boundary=null" ;;
        cgg-logo) echo "bundle/scenes/cgg-logo/scene.xml" ;;
        ad) echo "bundle/scenes/ad/scene.xml" ;;
        smoke) echo "bundle/scenes/smoke/scene.xml -D data=$DATA" ;;
        bucky) echo "bundle/scenes/bucky/scene.toml -D data=$DATA" ;;
        envmap-cube) echo "bundle/scenes/envmap-cube/scene.xml" ;;
        chromatic-cube) echo "bundle/scenes/chromatic/cube.xml" ;;
        chromatic-slab) echo "bundle/scenes/chromatic/slab.xml" ;;
        sun-slab) echo "bundle/scenes/lights/sun-slab.xml" ;;
        spot-fog) echo "bundle/scenes/lights/spot-fog.xml" ;;
        spot-fog-chromatic) echo "bundle/scenes/lights/spot-fog.xml -D sigma_t=0.25,0.5,1" ;;
        mesh-sphere-smooth) echo "bundle/scenes/mesh-peers/sphere.xml" ;;
        mesh-sphere-shaded) echo "bundle/scenes/mesh-peers/sphere.xml -D face_normals=false" ;;
        mesh-torus-rough) echo "bundle/scenes/mesh-peers/torus.xml" ;;
        *) echo "" ;;
    esac
}

compare() { # label backend res spp machine
    local label=$1 backend=$2 res=$3 spp=$4 machine=$5 failures=0
    for name in $SCENES; do
        args=$(scene_args "$name")
        [ -n "$args" ] || { log "SKIP $name: unknown scene"; continue; }
        # shellcheck disable=SC2086
        if "$PY" bench/peers/mitsuba3/compare.py $args --name "$name-$label" --backend "$backend" \
            --resolution "$res" --spp "$spp" --volpt "$VOLPT" --machine "$machine" --out "$RES_DIR" \
            >"$RES_DIR/$name-$label.log" 2>&1; then
            log "$(grep '^| ' "$RES_DIR/$name-$label.log" | tail -n 1)"
        else
            log "FAIL $name-$label: $(tail -n 3 "$RES_DIR/$name-$label.log" | tr '\n' ' ')"
            failures=$((failures + 1))
        fi
    done
    return $failures
}

if [ "$MODE" = print ]; then
    RECORDS=$RES_DIR/print
    if [ ! -f "$RECORDS/white/naive.toml" ]; then
        OUT=$RECORDS bash bundle/print.sh >"$RES_DIR/print-sh.log" 2>&1
        log "bundle/print.sh: $(tail -n 1 "$RECORDS/summary.txt" 2>/dev/null)"
    fi
    "$PY" bench/peers/mitsuba3/print.py --volpt "$VOLPT" --spp "${PRINT_SPP:-4096}" --fine lines \
        --uniform "$RECORDS/white" $(for t in ${PRINT_TARGETS:-lines photo gradient}; do echo "$RECORDS/$t"; done) \
        2>"$RES_DIR/print-mitsuba.log" \
        | tee -a "$RES_DIR/device-summary.txt"
    status=${PIPESTATUS[0]}
    log "print: $([ "$status" = 0 ] && echo PASS || echo "FAIL (status $status; $RES_DIR/print-mitsuba.log)")"
    exit "$status"
fi

failures=0
if [ "$MODE" = all ] || [ "$MODE" = gpu ]; then
    compare gpu cuda "$GPU_RES" "$GPU_SPP" "${GPU_NAME:-GPU}" || failures=$((failures + $?))
fi
if [ "$MODE" = all ] || [ "$MODE" = cpu ]; then
    # Mitsuba's llvm variants need a libLLVM (Debian: libllvm19); the device may not have one.
    if [ -z "${DRJIT_LIBLLVM_PATH:-}" ]; then
        DRJIT_LIBLLVM_PATH=$(ls /usr/lib/x86_64-linux-gnu/libLLVM*.so* /usr/lib/llvm-*/lib/libLLVM*.so* \
            /usr/local/lib/libLLVM*.so* /usr/lib64/libLLVM*.so* 2>/dev/null | sort -V | tail -n 1)
    fi
    if [ -n "$DRJIT_LIBLLVM_PATH" ]; then
        export DRJIT_LIBLLVM_PATH
        log "libLLVM: $DRJIT_LIBLLVM_PATH"
        compare cpu cpu "$CPU_RES" "$CPU_SPP" "$CPU_DESC" || failures=$((failures + $?))
    else
        log "SKIP cpu rows: no libLLVM on this machine (Mitsuba's llvm_ad_rgb needs one; set DRJIT_LIBLLVM_PATH)"
    fi
fi
log "results: $RES_DIR/results.md; $failures failed"
exit $((failures > 0))
