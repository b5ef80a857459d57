#!/usr/bin/env bash
# Where the time of a render goes: each engine's own reported time beside the sum of its kernels'
# durations (Nsight Compute, clocks not locked, one metric so one pass per launch; volpt's bench
# renders twice, a warm-up and the trial), for the thesis's
# regenerationSK binary and volpt on the thesis's cgg_logo XML (docs/strategies.md). From the
# bundle, with the thesis peer in bundle/thesis (as for thesis.sh):
#
#   bash bundle/kernel-times.sh     # $OUT/kernel-times.txt
#
# Knobs: RES (400), SPP (100), STRATEGIES (volpt's, default regeneration-sk regeneration-block-sk).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
PEER=$PWD/thesis
RES=${RES:-400}
SPP=${SPP:-100}
STRATEGIES=${STRATEGIES:-regeneration-sk regeneration-block-sk}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/kernel-times.XXXXXX")
REPORT=$OUT/kernel-times.txt
echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader); ${RES}x$RES, $SPP spp" >"$REPORT"
PEER_BIN=$PEER/bin
if [ ! -d "$PEER_BIN" ]; then
    PEER_BIN=$WORK/bin
    python3 -c 'import sys, tarfile
safe = {"filter": "data"} if hasattr(tarfile, "data_filter") else {}
tarfile.open(sys.argv[1]).extractall(sys.argv[2], **safe)' "$PEER/bin.tar.xz" "$WORK"
fi
python3 "$PEER/gen_scenes.py" "$WORK/scenes" >"$WORK/gen.log" 2>&1
CGG=$WORK/scenes/cgg_logo/volpath_bsdf.xml

kernels() { # kernels NAME RENDERS COMMAND...: launches and kernel time per render, under ncu
    local name=$1 renders=$2
    shift 2
    timeout 120 ncu --clock-control none --metrics gpu__time_duration.sum,smsp__inst_executed.sum,smsp__thread_inst_executed.sum --csv "$@" \
        >"$WORK/$name.csv" 2>"$WORK/$name.err"
    python3 - "$WORK/$name.csv" "$renders" <<'PY'
import csv, sys
rows = [r for r in csv.reader(open(sys.argv[1], errors="replace")) if len(r) > 10]
head = rows[0]
k, unit, value = head.index("Kernel Name"), head.index("Metric Unit"), head.index("Metric Value")
scale = {"nsecond": 1e-6, "ns": 1e-6, "usecond": 1e-3, "us": 1e-3, "msecond": 1.0, "ms": 1.0, "second": 1e3, "s": 1e3}
metric = head.index("Metric Name")
by = {}
for r in rows[1:]:
    name = r[k].split("(")[0].split("<")[0][-40:]
    entry = by.setdefault(name, {"ms": 0.0, "launches": 0, "inst": 0.0, "thread_inst": 0.0})
    v = float(r[value].replace(",", ""))
    if r[metric] == "gpu__time_duration.sum":
        entry["ms"] += v * scale[r[unit]]
        entry["launches"] += 1
    elif r[metric] == "smsp__inst_executed.sum":
        entry["inst"] += v
    elif r[metric] == "smsp__thread_inst_executed.sum":
        entry["thread_inst"] += v
renders = int(sys.argv[2])
print("; ".join(f"{name}: {e['launches'] / renders:g} launches, {e['ms'] / renders:.1f} ms, "
                f"{e['inst'] / renders / 1e9:.3f} G warp inst, "
                f"SIMT {100 * e['thread_inst'] / max(32 * e['inst'], 1):.0f}% per render"
                for name, e in by.items() if e["ms"] > 0.5 * renders))
PY
}

for rr in none thesis; do
    case $rr in
        none) volpt_rr=(--rr-depth -1); bin=$PEER_BIN/cvr_norr_stats ;;
        thesis) volpt_rr=(--roulette throughput --rr-depth 0); bin=$PEER_BIN/cvr_thread_stats ;;
    esac
    thesis=("$bin" "$CGG" --interactive false -a cudaVolPath -k regenerationSK -r "$RES" "$RES" -i "$SPP")
    wall=$("${thesis[@]}" --trials 3 -o "$WORK/t" 2>&1 | grep -o "wall mean time [0-9.]* sec" | grep -o "[0-9.]*")
    echo "thesis regenerationSK rr=$rr: own wall mean ${wall:-?} s; kernels $(kernels "thesis-$rr" 1 "${thesis[@]}" --trials 1 -o "$WORK/t")" >>"$REPORT"
    for s in $STRATEGIES; do
        volpt=("$VOLPT" bench "$CGG" --backend cuda --strategy "$s" --math fast "${volpt_rr[@]}"
            --resolution "${RES}x$RES" --spp "$SPP")
        mean=$("${volpt[@]}" --trials 3 --json 2>/dev/null | python3 -c 'import json,sys; print(json.load(sys.stdin)["time_mean_s"])')
        echo "volpt $s fast rr=$rr: bench mean ${mean:-?} s; kernels $(kernels "volpt-$s-$rr" 2 "${volpt[@]}" --trials 1)" >>"$REPORT"
    done
done
cat "$REPORT"
