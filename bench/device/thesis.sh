#!/usr/bin/env bash
# The thesis's own CUDA renderer (github Fe0437/CudaVolumeRenderer, built as in
# ../shared/peers/thesis/README.md) beside volpt on the SAME Mitsuba XML files (the thesis repo's
# cgg_logo and ad, grids regenerated), same GPU, same run. From the bundle, on the device:
#
#   bash bundle/thesis.sh          # results in $OUT/thesis.txt (default ./out)
#
# It expects the peer under bundle/thesis/: bin.tar.xz (or bin/) with cvr_<variant> (nvcc 13, sm_90,
# CUDA runtime and libstdc++ linked statically, stripped; only libc and the driver's libcuda are
# loaded), lib/ (shared libraries, if a build needs any), gen_scenes.py (numpy only), textures.npz
# and xml/. They are built outside this repository (assemble.sh and build.sh of
# ../shared/peers/thesis; BUILD.md beside them says how) and copied in:
# `cp -r THESIS_PEER/device bundle/thesis`.
#
# Runs, each scene at 400x400, 100 spp, one discarded warm-up and TRIALS timed trials:
# - thesis: regenerationSK at thread, warp and block level and streamingSK with compaction, with
#   its roulette (cvr_{thread,warp,block,compact}_stats) and, where the peer carries the build,
#   without (cvr_norr{,_block,_compact}_stats);
# - volpt: regeneration-sk, regeneration-block-sk, streaming-sk, exact and fast math, without
#   roulette (--rr-depth -1) and with the thesis's (--roulette throughput --rr-depth 0: survival
#   min(1, max T) after every interaction, as the thesis code does); regeneration-sk (exact) with volpt's
#   default (Mitsuba's rule from depth 5).
# Both count a segment per free flight or boundary event ("rays" in the thesis code); times are
# wall-clock means of the timed trials (the thesis: host clock around render(); volpt: `volpt bench`).
# Image means (thesis: its .hdr, RGBE decoded at the bin centres; volpt: bench's image_mean) show
# that both render the same scene.
# volpt reads its grids as each of LOOKUPS says (default "trilinear texture": software trilinear
# lookups of f32 grids, and the texture unit's filter, as the thesis reads its grids); a lookup
# other than trilinear is named in the strategy column (regeneration-sk/texture).
# Knobs: TRIALS (5), T (seconds per command, 60), DEADLINE (seconds after which runs are skipped,
# 210), BACKEND (cuda; cpu tests the volpt side without a GPU), RES (400), SPP (100), SCENES,
# LOOKUPS.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
PEER=$PWD/thesis
TRIALS=${TRIALS:-5}
T=${T:-60}
DEADLINE=${DEADLINE:-210}
BACKEND=${BACKEND:-cuda}
RES=${RES:-400}
SPP=${SPP:-100}
SCENES=${SCENES:-cgg_logo ad}
LOOKUPS=${LOOKUPS:-trilinear texture}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/thesis.XXXXXX")
RESULTS=$OUT/thesis-runs.tsv
LOGS=$WORK/logs
mkdir -p "$LOGS" "$WORK/img"
[ -d "$PEER/lib" ] && export LD_LIBRARY_PATH=$PEER/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
START=$SECONDS
why() { # why LOG: the lines of a failed command's log that say why, on one line
    { grep -m 2 -i -E "error|what\(\)|abort" "$1" || tail -n 2 "$1"; } | tr '\n' ' '
}
failures=0
log() { echo "== $*" | tee -a "$OUT/thesis-log.txt"; }
limit() { # the time a command may take: T, less near the deadline; fails past the deadline
    local left=$((DEADLINE - (SECONDS - START)))
    [ "$left" -le 0 ] && return 1
    echo $((left + 20 < T ? left + 20 : T))
}

: >"$OUT/thesis-log.txt"
log "date $(date -u +%Y-%m-%dT%H:%MZ) backend $BACKEND ${RES}x$RES $SPP spp, $TRIALS trials after a warm-up"
nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv,noheader \
    >"$OUT/device.txt" 2>&1
columns=(scene engine estimator strategy math time_mean_s segments_per_s paths_per_s segments_per_path mean_r mean_g mean_b)
(IFS=$'\t'; echo "${columns[*]}") >"$RESULTS"

# The binaries travel as one xz tarball (they share most of their bytes), unpacked by python's lzma
# (no xz needed) into the work directory.
PEER_BIN=$PEER/bin
if [ "$BACKEND" = cuda ] && [ ! -d "$PEER_BIN" ]; then
    PEER_BIN=$WORK/bin
    python3 -c 'import sys, tarfile
safe = {"filter": "data"} if hasattr(tarfile, "data_filter") else {}
tarfile.open(sys.argv[1]).extractall(sys.argv[2], **safe)' "$PEER/bin.tar.xz" "$WORK" \
        || { log "FAIL unpacking $PEER/bin.tar.xz"; exit 1; }
fi
python3 "$PEER/gen_scenes.py" "$WORK/scenes" >"$LOGS/gen.log" 2>&1 \
    || { log "FAIL gen_scenes: $(why "$LOGS/gen.log")"; exit 1; }

run_thesis() { # run_thesis SCENE ESTIMATOR STRATEGY BINARY KERNEL
    local scene=$1 est=$2 strategy=$3 bin=$PEER_BIN/cvr_$4 kernel=$5 tmo name
    name=thesis-$scene-$est-$strategy
    [ -x "$bin" ] || { log "SKIP $name: the peer has no $bin"; return; }
    tmo=$(limit) || { log "SKIP $name (deadline)"; return; }
    if timeout "$tmo" "$bin" "$WORK/scenes/$scene/volpath_bsdf.xml" --interactive false -a cudaVolPath -k "$kernel" \
        -r "$RES" "$RES" -i "$SPP" --trials $((TRIALS + 1)) -o "$WORK/img/$name" >"$LOGS/$name.log" 2>&1 \
        && python3 - "$LOGS/$name.log" "$WORK/img/$name.hdr" "$scene" "$est" "$strategy" >>"$RESULTS" <<'PY'
import re, sys
from rgbe import read_rgbe
log, hdr, scene, est, strategy = sys.argv[1:]
text = open(log, errors="replace").read()
# "[spike] wall mean time 0.1220 sec, paths per sec 1.3e7, mean rays 9.6e8, Mrays per sec (wall) 7900.1"
m = re.search(r"\[spike\] wall mean time ([\d.]+) sec, paths per sec ([\d.]+), mean rays (\d+), "
              r"Mrays per sec \(wall\) ([\d.]+)", text)
if m is None:
    sys.exit(f"{log}: no '[spike] wall mean time ... Mrays per sec (wall)' line")
t, paths_s, rays, mrays_s = (float(g) for g in m.groups())

mean = read_rgbe(hdr).reshape(-1, 3).mean(0)
print("\t".join([scene, "thesis", est, strategy, "-", f"{t:.6g}", f"{mrays_s * 1e6:.6g}", f"{paths_s:.6g}",
                 f"{rays / (paths_s * t):.4g}"] + [f"{v:.6g}" for v in mean]))
PY
    then log "ok $name"
    else log "FAIL $name (exit $?): $(why "$LOGS/$name.log")"; failures=$((failures + 1))
    fi
}

run_volpt() { # run_volpt SCENE ESTIMATOR STRATEGY MATH VOLPT-ARGS..., grids read as $LOOKUP says
    local scene=$1 est=$2 strategy=$3 math=$4 tmo name label gpu=()
    shift 4
    label=$strategy
    [ "${LOOKUP:-trilinear}" = trilinear ] || label=$strategy/$LOOKUP
    name=volpt-$scene-$est-${label//\//-}-$math
    tmo=$(limit) || { log "SKIP $name (deadline)"; return; }
    [ "$BACKEND" = cuda ] && gpu=(--strategy "$strategy" --math "$math")
    if timeout "$tmo" "$VOLPT" bench "$WORK/scenes/$scene/volpath_bsdf.xml" --backend "$BACKEND" "${gpu[@]}" "$@" \
        --lookup "${LOOKUP:-trilinear}" --resolution "${RES}x$RES" --spp "$SPP" --trials "$TRIALS" --json \
        >"$LOGS/$name.json" 2>"$LOGS/$name.err" \
        && python3 - "$LOGS/$name.json" "$scene" "$est" "$label" "$math" >>"$RESULTS" <<'PY'
import json, sys
path, scene, est, strategy, math = sys.argv[1:]
r = json.load(open(path))
print("\t".join([scene, "volpt", est, strategy, math, f"{r['time_mean_s']:.6g}", f"{r['segments_per_s']:.6g}",
                 f"{r['paths_per_s']:.6g}", f"{r['segments'] / r['paths']:.4g}"]
                + [f"{v:.6g}" for v in r["image_mean"]]))
PY
    then log "ok $name"
    else log "FAIL $name (exit $?): $(why "$LOGS/$name.err")"; failures=$((failures + 1))
    fi
}

thesis_runs() { # thesis_runs STRATEGY KERNEL ROULETTE-BINARY NO-ROULETTE-BINARY, for every scene
    [ "$BACKEND" = cuda ] || return 0
    for scene in $SCENES; do
        run_thesis "$scene" no-roulette "$1" "$4" "$2"
        run_thesis "$scene" thesis-roulette "$1" "$3" "$2"
    done
}
volpt_runs() { # volpt_runs STRATEGY, for every scene, math and lookup
    for scene in $SCENES; do
        for LOOKUP in $LOOKUPS; do
            for math in exact fast; do
                run_volpt "$scene" no-roulette "$1" "$math" --rr-depth -1
                run_volpt "$scene" thesis-roulette "$1" "$math" --roulette throughput --rr-depth 0
            done
        done
    done
}
# The most telling comparison first, so that the deadline cuts the least important runs.
thesis_runs regenerationSK-thread regenerationSK thread_stats norr_stats
volpt_runs regeneration-sk
thesis_runs regenerationSK-block regenerationSK block_stats norr_block_stats
volpt_runs regeneration-block-sk
thesis_runs streamingSK-compaction streamingSK compact_stats norr_compact_stats
volpt_runs streaming-sk
LOOKUP=trilinear
for scene in $SCENES; do
    run_thesis "$scene" thesis-roulette regenerationSK-warp warp_stats regenerationSK
    run_volpt "$scene" mitsuba-roulette-5 regeneration-sk exact --roulette mitsuba --rr-depth 5
done

python3 - "$RESULTS" >"$OUT/thesis.txt" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
print("# thesis binary vs volpt, same XML files, same GPU, same run; time: wall mean of the timed trials")
print(f"| {'scene':<8} | {'estimator':<18} | {'engine':<6} | {'strategy':<22} | {'math':<5} | {'time s':>8} | "
      f"{'G seg/s':>7} | {'M paths/s':>9} | {'seg/path':>8} | {'image mean (RGB)':<26} |")
print("|" + "|".join("-" * w for w in (10, 20, 8, 24, 7, 10, 9, 11, 10, 28)) + "|")
order = {"no-roulette": 0, "thesis-roulette": 1, "mitsuba-roulette-5": 2}
for r in sorted(rows, key=lambda r: (r["scene"], order.get(r["estimator"], 9), r["engine"] != "thesis")):
    mean = " ".join(f"{float(r[c]):.4f}" for c in ("mean_r", "mean_g", "mean_b"))
    print(f"| {r['scene']:<8} | {r['estimator']:<18} | {r['engine']:<6} | {r['strategy']:<22} | {r['math']:<5} | "
          f"{float(r['time_mean_s']):8.4f} | {float(r['segments_per_s']) / 1e9:7.3f} | "
          f"{float(r['paths_per_s']) / 1e6:9.2f} | {float(r['segments_per_path']):8.2f} | {mean:<26} |")
PY
cat "$OUT/thesis.txt"
log "failures: $failures, $((SECONDS - START)) s"
(cd "$WORK" && tar czf "$OUT/thesis-logs.tar.gz" logs)
rm -rf "$WORK"
exit $((failures > 0))
