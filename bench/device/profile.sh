#!/usr/bin/env bash
# Nsight Compute profiles of volpt's kernels beside the thesis's own (Fe0437/CudaVolumeRenderer)
# on the same scene file, to see where volpt's time per path and per segment goes
# (docs/strategies.md). From the bundle, on the device, with the thesis peer copied to
# bundle/thesis as for thesis.sh:
#
#   bash bundle/profile.sh        # $OUT/profile.txt (summary), $OUT/profile.tar.gz (details)
#
# Profiles (one launch each, `ncu --set full`), at 400x400, SPP samples per pixel:
# - cgg_logo (the thesis's XML) with the thesis's roulette (about 5 segments per path: per-path
#   cost) and without roulette (about 60: per-segment cost): volpt regeneration-sk, fast math, and
#   the thesis's regenerationSK (thread level);
# - volpt's index-matched homogeneous cube (scenes/homogeneous-cube, -Dboundary=null) with regeneration-block-sk.
# For each: ncu's details page, the per-opcode instruction counts and the SASS lines with the
# most warp-stall samples (profile.tar.gz), and a summary line (profile.txt): duration, registers,
# achieved occupancy, issue slots busy, instructions executed per path and per segment.
# Knobs: SPP (16: ncu replays the kernel ~40 times), BACKEND must be cuda.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
PEER=$PWD/thesis
SPP=${SPP:-16}
RES=${RES:-400}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/profile.XXXXXX")
mkdir -p "$WORK/details"
SUMMARY=$OUT/profile.txt
log() { echo "== $*" | tee -a "$SUMMARY"; }
: >"$SUMMARY"
log "date $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader) $(ncu --version | tail -1)"

PEER_BIN=$PEER/bin
if [ ! -d "$PEER_BIN" ] && [ -f "$PEER/bin.tar.xz" ]; then
    PEER_BIN=$WORK/bin
    python3 -c 'import sys, tarfile
safe = {"filter": "data"} if hasattr(tarfile, "data_filter") else {}
tarfile.open(sys.argv[1]).extractall(sys.argv[2], **safe)' "$PEER/bin.tar.xz" "$WORK"
fi
[ -f "$PEER/gen_scenes.py" ] && python3 "$PEER/gen_scenes.py" "$WORK/scenes" >"$WORK/gen.log" 2>&1
CGG=$WORK/scenes/cgg_logo/volpath_bsdf.xml

profile() { # profile NAME KERNEL-REGEX PATHS COMMAND...: one launch, full set
    local name=$1 kernel=$2 paths=$3
    shift 3
    if ! timeout 240 ncu --set full --import-source no -k "regex:$kernel" --launch-count 1 \
        -o "$WORK/$name" "$@" >"$WORK/details/$name.log" 2>&1; then
        log "FAIL $name: $(tail -n 3 "$WORK/details/$name.log" | tr '\n' ' ')"
        return
    fi
    ncu -i "$WORK/$name.ncu-rep" --page details >"$WORK/details/$name-details.txt" 2>&1
    ncu -i "$WORK/$name.ncu-rep" --page raw --csv >"$WORK/details/$name-raw.csv" 2>&1
    ncu -i "$WORK/$name.ncu-rep" --page source --print-source sass --csv \
        >"$WORK/$name-sass.csv" 2>"$WORK/details/$name-sass.err"
    python3 - "$WORK" "$name" "$paths" >>"$SUMMARY" <<'PY'
import csv, io, sys
work, name, paths = sys.argv[1], sys.argv[2], float(sys.argv[3])
rows = list(csv.reader(open(f"{work}/details/{name}-raw.csv", errors="replace")))
head = next(i for i, r in enumerate(rows) if "Kernel Name" in r)
names, units, values = rows[head], rows[head + 1], rows[head + 2]
raw = dict(zip(names, values))
def num(key):
    try:
        return float(raw[key].replace(",", ""))
    except (KeyError, ValueError):
        return float("nan")
inst = num("smsp__inst_executed.sum")
thread_inst = num("smsp__thread_inst_executed.sum")
line = (f"{name}: kernel {raw.get('Kernel Name', '?')[:60]} | duration {num('gpu__time_duration.sum') / 1e6:.3f} ms"
        f" | registers {raw.get('launch__registers_per_thread', '?')}"
        f" | occupancy achieved {num('sm__warps_active.avg.pct_of_peak_sustained_active'):.1f}%"
        f" theoretical {num('sm__maximum_warps_per_active_cycle_pct'):.1f}%"
        f" | issue busy {num('sm__inst_issued.avg.pct_of_peak_sustained_active'):.1f}%"
        f" | warp inst/path {inst / paths:.1f}, thread inst/path {thread_inst / paths:.1f}"
        f" | SIMT efficiency {100 * thread_inst / max(inst * 32, 1):.1f}%")
print(line)
# Instructions executed per opcode (the instruction-statistics section's raw metrics).
ops = sorted(((num(k), k.split("sass__inst_executed_per_opcode")[-1]) for k in names
              if k.startswith("sass__inst_executed_per_opcode")), reverse=True)
with open(f"{work}/details/{name}-opcodes.txt", "w") as f:
    for v, k in ops[:40]:
        f.write(f"{k:<50} {v:14.0f} {v / paths:9.2f}/path\n")
# The SASS lines with the most warp-stall samples.
try:
    text = open(f"{work}/{name}-sass.csv", errors="replace").read()
    sass = list(csv.DictReader(io.StringIO(text[text.index('"'):])))
    key = next(k for k in sass[0] if "Warp Stall Sampling (All" in k)
    exe = next((k for k in sass[0] if k.startswith("Instructions Executed")), None)
    sass.sort(key=lambda r: -float(r[key].replace(",", "") or 0))
    total = sum(float(r[key].replace(",", "") or 0) for r in sass)
    with open(f"{work}/details/{name}-sass-top.txt", "w") as f:
        f.write(f"# {len(sass)} SASS instructions, {total:.0f} stall samples; top 80 by samples\n")
        for r in sass[:80]:
            s = float(r[key].replace(",", "") or 0)
            f.write(f"{100 * s / max(total, 1):5.1f}% {r.get('Address', '')} {r.get('Source', '')[:90]}"
                    f"  exec {r.get(exe, '') if exe else ''}\n")
except Exception as e:  # the source page is a convenience: report, do not fail the summary
    print(f"  ({name}: no SASS table: {e})")
PY
}

paths=$((RES * RES * SPP))
if [ -f "$CGG" ]; then
    for rr in thesis none; do
        case $rr in
            thesis) args=(--roulette throughput --rr-depth 0); k=thread_stats ;;
            none) args=(--rr-depth -1); k=norr_stats ;;
        esac
        profile "volpt-cgg-rr-$rr" "regeneration_sk__" "$paths" \
            "$VOLPT" render "$CGG" --backend cuda --strategy regeneration-sk --math fast "${args[@]}" \
            --resolution "${RES}x$RES" --spp "$SPP" -o "$WORK/volpt-cgg-$rr.exr"
        [ -x "$PEER_BIN/cvr_$k" ] && profile "thesis-cgg-rr-$rr" "d_render" "$paths" \
            "$PEER_BIN/cvr_$k" "$CGG" --interactive false -a cudaVolPath -k regenerationSK \
            -r "$RES" "$RES" -i "$SPP" --trials 1 -o "$WORK/thesis-cgg-$rr"
    done
else
    log "SKIP the thesis scenes: no $PEER/gen_scenes.py (copy the peer to bundle/thesis)"
fi
"$VOLPT" scene generate scenes >/dev/null 2>&1
profile volpt-cube-block "regeneration_block_sk__" "$paths" \
    "$VOLPT" render scenes/homogeneous-cube/scene.xml -Dboundary=null --backend cuda --strategy regeneration-block-sk \
    --math fast --resolution "${RES}x$RES" --spp "$SPP" -o "$WORK/cube.exr"

tar czf "$OUT/profile.tar.gz" -C "$WORK" details
log "done"
