#!/usr/bin/env bash
# `volpt view` measured end to end (render + tone map + JPEG + send, as a page receives it) by a
# scripted client, for the included scenes, CPU and GPU, at 800x800 and 1920x1080. Run on the
# device machine from the bundle (`cargo xtask device-bundle`, which carries bin/viewer-bench):
#
#   bash bundle/viewer.sh                  # $OUT/viewer.md (a table) and $OUT/viewer.jsonl
#   SCENES="example-cube" BACKENDS=cuda SECONDS_PER_PHASE=2 bash bundle/viewer.sh   # a quick look
#
# Each run starts `volpt view SCENE --backend B --resolution R --bind 127.0.0.1:0`, runs
# bin/viewer-bench against it (see volpt-view/examples/viewer_bench.rs: the time from a still
# camera move to its first frame, frames/s of the still refinement, frames/s and move-to-frame time
# while orbiting at 60 moves/s; a view shown again must give its first image byte for byte), and
# stops the server with Ctrl-C (SIGINT), which must end it.
#
# First, with BACKENDS including cuda, the frames' GPU checks (CHECKS=0 skips them, ~40 s):
#   1. `volpt selftest` (exact and fast kernels): its "tone mapping" line must PASS: the GPU's
#      tone-mapped frame equals the CPU's within one 8-bit level.
#   2. the accumulation: a scene served, dragged away and moved back (bin/viewer-bench
#      --snapshot), its linear image once the still view has all its samples, from the GPU and
#      from the CPU: the example cube (64x48, 64 spp, regeneration-sk) and ad (128x128, 8 spp,
#      streaming-mk: frames stopped at their deadline with paths in flight, continued by the next;
#      the line says how many still frames had paths in flight). The GPU's exact kernels must
#      give the CPU's seed-0 image up to rounding (`volpt compare --max-relative 1e-4`), and the
#      GPU's exact and fast images must be independent estimates of the CPU's seed-1 image
#      (`--independent`). The CPU's viewer image is `volpt render`'s bit for bit
#      (volpt-view/tests/accumulation.rs).
#
# Issue 41's look at the frames (the checks, then the cube and ad on the GPU at 800x800 with
# regeneration-sk and with streaming-mk; ~100 s):
#   SCENES="example-cube ad" BACKENDS=cuda STRATEGIES="regeneration-sk streaming-mk" \
#       RESOLUTIONS=800x800 SECONDS_PER_PHASE=2 bash bundle/viewer.sh
#
# Environment:
#   OUT                 outputs (default ./out)
#   SCENES, BACKENDS, RESOLUTIONS   space-separated subsets of the lists below
#   SECONDS_PER_PHASE   seconds of the still and orbit phases each (default 3)
#   LIMIT               seconds per run before it is killed and reported (default 90)
#   STRATEGY, MATH      the GPU's (default regeneration-sk: no calibration; exact)
#   STRATEGIES          several GPU strategies, each a row (e.g. "regeneration-sk streaming-mk":
#                       a multi-kernel strategy's frames stop at their deadline with paths in flight)
#   DATA                a folder with smoke.vol and Bucky.raw (default: the bundle's data/)
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
SECONDS_PER_PHASE=${SECONDS_PER_PHASE:-3}
LIMIT=${LIMIT:-90}
STRATEGY=${STRATEGY:-regeneration-sk}
STRATEGIES=${STRATEGIES:-$STRATEGY}
MATH=${MATH:-exact}
BACKENDS=${BACKENDS:-cuda cpu}
RESOLUTIONS=${RESOLUTIONS:-800x800 1920x1080}
VOLPT=bin/volpt
CLIENT=bin/viewer-bench
mkdir -p "$OUT"
MD=$OUT/viewer.md
JSONL=$OUT/viewer.jsonl
: >"$JSONL"
say() { echo "$*" | tee -a "$MD"; }
[ -x "$CLIENT" ] || { echo "viewer.sh: $CLIENT is missing (cargo build --release -p volpt-view --example viewer_bench; copy target/release/examples/viewer_bench there)"; exit 1; }

data_param() { # data_param FILE: prints -Ddata=DIR if DIR/FILE exists
    local dir=${DATA:-$PWD/data}
    if [ -f "$dir/$1" ]; then echo "-Ddata=$dir"; fi
}
declare -A FILES=(
    [example-cube]="scenes/example/cube.xml"
    [homogeneous-cube]="scenes/homogeneous-cube/scene.xml"
    [cgg-logo]="scenes/cgg-logo/scene.xml"
    [ad]="scenes/ad/scene.xml"
    [envmap-cube]="scenes/envmap-cube/scene.xml"
    [smoke]="scenes/smoke/scene.xml $(data_param smoke.vol)"
    [bucky]="scenes/bucky/scene.toml $(data_param Bucky.raw)"
)
SCENES=${SCENES:-example-cube homogeneous-cube cgg-logo ad envmap-cube smoke bucky}

: >"$MD"
say "# volpt view, end to end, $(date -u +%Y-%m-%dT%H:%MZ)"
say ""
say "device: $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null | head -n 1); CPU: $(nproc) threads of $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
say "volpt: $($VOLPT --version 2>/dev/null); GPU strategy $STRATEGIES, math $MATH; phases of $SECONDS_PER_PHASE s"
say ""
say "move->frame: a still camera move to its first frame (1 spp, full resolution), median of 10. still: frames/s of the refinement and the spp reached. orbit: 60 interactive moves/s; frames/s showing a move, move->frame median, the resolution the renderer chose, and the mean setup (the moves checked and applied, the epoch started) / render / tone map / JPEG ms per frame."
say ""
"$VOLPT" scene generate scenes >"$OUT/viewer-generate.log" 2>&1 || echo "viewer.sh: volpt scene generate failed (see viewer-generate.log)"

# serve NAME ARGS...: starts `volpt view ARGS --bind 127.0.0.1:0` logging to $OUT/viewer-NAME.log;
# sets $server and $url (empty if it did not start).
serve() {
    local name=$1; shift
    log=$OUT/viewer-$name.log
    "$VOLPT" view "$@" --bind 127.0.0.1:0 >"$log" 2>&1 &
    server=$!
    url=
    for _ in $(seq 600); do
        url=$(sed -n 's/^volpt view: open http/ws/p' "$log")
        [ -n "$url" ] && break
        kill -0 "$server" 2>/dev/null || break
        sleep 0.1
    done
}
# stop: Ctrl-C the server, which must end it.
stop() {
    kill -INT "$server" 2>/dev/null
    for _ in $(seq 100); do kill -0 "$server" 2>/dev/null || break; sleep 0.1; done
    if kill -0 "$server" 2>/dev/null; then
        echo "viewer.sh: $log: the server ignored SIGINT" | tee -a "$log"; kill -9 "$server"; failures=$((failures + 1))
    fi
    wait "$server" 2>/dev/null
}
failures=0
check() { # check NAME COMMAND...: one line, PASS or FAIL, with the command's last line
    local name=$1; shift
    local out; out=$("$@" 2>&1); local rc=$?
    if [ $rc -eq 0 ]; then say "- PASS $name: $(echo "$out" | tail -n 1)"; else
        say "- FAIL $name: $(echo "$out" | tail -n 3 | tr '\n' ' ')"; failures=$((failures + 1)); fi
}
if [ "${CHECKS:-1}" = 1 ] && [[ " $BACKENDS " == *" cuda "* ]]; then
    say "## The frames' GPU checks"
    say ""
    for math in exact fast; do
        "$VOLPT" selftest --math $math >"$OUT/viewer-selftest-$math.log" 2>&1
        check "tone mapping ($math kernels)" grep -E "^PASS tone mapping" "$OUT/viewer-selftest-$math.log"
        say "  $(grep -A1 'tone mapping' "$OUT/viewer-selftest-$math.log" | tail -n 1 | xargs)"
    done
    # accumulate NAME SCENE-ARGS -- RUNS...: serves each run ("name flags...") of the scene,
    # drags away and back, and keeps the still view's linear image as $OUT/accumulation-NAME-RUN.exr.
    accumulate() {
        local scene=$1; shift
        local args=(); while [ "$1" != -- ]; do args+=("$1"); shift; done; shift
        for run in "$@"; do
            # shellcheck disable=SC2086 # the run's name and flags
            set -- $run
            local name=$1; shift
            serve "accumulation-$scene-$name" "${args[@]}" "$@"
            rm -f "$OUT/accumulation-$scene-$name.exr"
            if [ -n "$url" ]; then
                timeout 60 "$CLIENT" "${url}ws" --snapshot "$OUT/accumulation-$scene-$name.exr" \
                    >"$OUT/accumulation-$scene-$name.json" 2>>"$log"
                say "  $scene $name: $(python3 -c "import json,sys
try:
    r = json.load(sys.stdin); print(f\"{r['last']['spp']} spp, {r['last']['width']}x{r['last']['height']}, {r['still_frames_with_paths_in_flight']} still frames with paths in flight\")
except Exception as e: print('no snapshot:', e)" <"$OUT/accumulation-$scene-$name.json")"
            fi
            stop
        done
    }
    # The cube with the default strategy's kernels; ad (paths of ~140 segments, a few of
    # thousands) with streaming-mk, whose frames stop at their deadline with paths in flight.
    accumulate cube scenes/example/cube.xml --resolution 64x48 --spp 64 -- \
        "gpu-exact --backend cuda --strategy regeneration-sk --math exact" \
        "gpu-fast --backend cuda --strategy regeneration-sk --math fast" \
        "cpu-0 --backend cpu" "cpu-1 --backend cpu --seed 1"
    accumulate ad scenes/ad/scene.xml --resolution 128x128 --spp 8 -- \
        "gpu-exact --backend cuda --strategy streaming-mk --math exact" \
        "gpu-fast --backend cuda --strategy streaming-mk --math fast" \
        "cpu-0 --backend cpu" "cpu-1 --backend cpu --seed 1"
    for scene in cube ad; do
        a=$OUT/accumulation-$scene
        check "accumulation, $scene: the GPU's exact image is the CPU's (seed 0)" \
            "$VOLPT" compare "$a-gpu-exact.exr" "$a-cpu-0.exr" --max-relative 1e-4
        for math in exact fast; do
            check "accumulation, $scene: the GPU's $math image estimates the CPU's seed-1 image" \
                "$VOLPT" compare "$a-gpu-$math.exr" "$a-cpu-1.exr" --independent
        done
    done
    say ""
fi

num() { python3 -c "import json,sys; v=json.loads(sys.argv[1]).get(sys.argv[2]); print('-' if v is None else (f'{v:.1f}' if isinstance(v,float) else v))" "$1" "$2"; }
say "| scene | backend | resolution | move->frame ms | still frames/s | still spp after | orbit frames/s | orbit move->frame ms | orbit at | orbit setup / render / tone / jpeg ms |"
say "|---|---|---|---|---|---|---|---|---|---|"
# The backends to run: the CPU, and the GPU once per strategy of STRATEGIES.
configs=()
for backend in $BACKENDS; do
    if [ "$backend" = cuda ]; then
        for strategy in $STRATEGIES; do configs+=("cuda:$strategy"); done
    else
        configs+=("$backend:")
    fi
done
for scene in $SCENES; do
  for config in "${configs[@]}"; do
    backend=${config%%:*} strategy=${config#*:}
    for res in $RESOLUTIONS; do
      # The backend column names the strategy where several run.
      gpu=() label=$backend
      if [ "$backend" = cuda ]; then
          gpu=(--strategy "$strategy" --math "$MATH")
          [ "$STRATEGIES" != "$STRATEGY" ] && label="cuda $strategy"
      fi
      # shellcheck disable=SC2086 # FILES holds the scene file and its -D parameter
      serve "$scene-${label// /-}-$res" ${FILES[$scene]} --backend "$backend" "${gpu[@]}" --resolution "$res"
      if [ -z "$url" ]; then
          say "| $scene | $label | $res | FAIL: no server ($(tail -n 1 "$log")) |"
          failures=$((failures + 1)); kill "$server" 2>/dev/null; wait "$server" 2>/dev/null; continue
      fi
      json=$(timeout "$LIMIT" "$CLIENT" "${url}ws" "$SECONDS_PER_PHASE" 2>>"$log")
      rc=$?
      stop
      if [ $rc -ne 0 ] || [ -z "$json" ]; then
          say "| $scene | $label | $res | FAIL: client rc $rc ($(tail -n 1 "$log")) |"
          failures=$((failures + 1)); continue
      fi
      echo "{\"scene\":\"$scene\",\"resolution\":\"$res\",\"result\":$json}" >>"$JSONL"
      if [ "$(num "$json" repeat_identical)" != True ]; then
          say "| $scene | $label | $res | FAIL: a view shown again is not its first image ($(num "$json" repeat_identical)) |"
          failures=$((failures + 1))
      fi
      say "| $scene | $label | $res | $(num "$json" still_move_to_frame_ms_median) | $(num "$json" still_frames_per_s) | $(num "$json" still_spp_after) | $(num "$json" orbit_frames_per_s) | $(num "$json" orbit_move_to_frame_ms_median) | $(num "$json" orbit_resolution) | $(num "$json" orbit_setup_ms_mean) / $(num "$json" orbit_render_ms_mean) / $(num "$json" orbit_tonemap_ms_mean) / $(num "$json" orbit_encode_ms_mean) |"
    done
  done
done
say ""
say "failures: $failures"
exit $((failures > 0))
