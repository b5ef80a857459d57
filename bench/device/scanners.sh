#!/usr/bin/env bash
# Scanner volumes on the GPU (issue 42, docs/guide.md "Scanner volumes"), run on the device machine
# from the bundle that `cargo xtask device-bundle` builds (it copies scenes/, with
# scenes/scanners/fixtures written by pynrrd, tifffile and pydicom):
#
#   cargo xtask device-bundle && bash bundle/scanners.sh    # results under $OUT (default ./out-scanners)
#
# scenes/scanners/scene.toml renders each fixture (NRRD raw/gzip/detached/mirrored/permuted, TIFF
# u16/u8-deflate/f32/folder, DICOM axial/mirrored/coronal) in the same box with a transfer function:
# on the GPU (naive-sk, exact math, 4 spp, seed 7, 64x64) every image must equal the reference
# .mha's GPU image bit for bit, and the reference's GPU image its CPU image.
#
# Files under $OUT: summary.txt (PASS/FAIL lines), device.txt, logs.tar.gz. Expected: 13 PASS
# lines and "failures: 0".
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out-scanners}
WORK=${WORK:-$PWD/scanners-work}
mkdir -p "$OUT" "$WORK/logs"
VOLPT=$PWD/bin/volpt
export RUST_BACKTRACE=1
failures=0

log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
run() {
    local name=$1; shift
    timeout 300 "$@" >"$WORK/logs/$name.log" 2>&1
    local rc=$?
    echo "(exit $rc: $*)" >>"$WORK/logs/$name.log"
    return $rc
}
fail() { log "FAIL $*"; failures=$((failures + 1)); }
tail_of() { tail -n "${2:-4}" "$WORK/logs/$1.log" | tr '\n' ' '; }
same() { # same NAME A.exr B.exr: bit-identical or FAIL
    if run "$1" "$VOLPT" compare "$2" "$3" --identical; then log "PASS $1: $(tail_of "$1" 2)"
    else fail "$1: $(tail_of "$1" 2)"; fi
}

log "date $(date -u +%Y-%m-%dT%H:%MZ)"
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv >"$OUT/device.txt" 2>&1
cat "$OUT/device.txt" | tee -a "$OUT/summary.txt"

SCENE=scenes/scanners/scene.toml
COMMON=(--spp 4 --seed 7 --resolution 64x64)
GPU=(--backend cuda --strategy naive-sk --math exact)
run reference-gpu "$VOLPT" render "$SCENE" "${COMMON[@]}" "${GPU[@]}" -o "$WORK/reference-gpu.exr" \
    || fail "reference.mha on the GPU: $(tail_of reference-gpu)"
run reference-cpu "$VOLPT" render "$SCENE" "${COMMON[@]}" -o "$WORK/reference-cpu.exr" \
    || fail "reference.mha on the CPU: $(tail_of reference-cpu)"
same reference-cpu-vs-gpu "$WORK/reference-cpu.exr" "$WORK/reference-gpu.exr"
for f in raw.nrrd gzip.nrrd detached.nhdr mirrored-x.nrrd permuted-xy.nrrd stack-u16.tif \
    stack-u8-deflate.tif stack-f32.tif tiff-folder dicom-axial dicom-mirrored dicom-coronal; do
    run "$f-gpu" "$VOLPT" render "$SCENE" -Dvolume="fixtures/$f" "${COMMON[@]}" "${GPU[@]}" \
        -o "$WORK/$f-gpu.exr" || { fail "$f on the GPU: $(tail_of "$f-gpu")"; continue; }
    same "$f-vs-reference-gpu" "$WORK/reference-gpu.exr" "$WORK/$f-gpu.exr"
done

tar -czf "$OUT/logs.tar.gz" -C "$WORK" logs
log "failures: $failures"
[ "$failures" -eq 0 ]
