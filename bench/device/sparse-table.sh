#!/usr/bin/env bash
# Issue 43's brick tables (volpt-core/src/sparse.rs: two-level on the host, flat on the GPU) on the
# device, one call:
#
#   bash bundle/sparse-table.sh     # AFTER=bin/volpt (this branch), BEFORE=bin/volpt-before (an
#                                   # earlier main, ca0b929 or later); results in $OUT/sparse-table.txt
#
# 1. Exact: with AFTER, naive-sk exact math, 4 spp, seed 7, 200x200:
#    - scenes/vdb/bucky.toml (bucky.vdb kept sparse) equals scenes/bucky/scene.toml (dense) bit for
#      bit, and equals BEFORE's image of the same sparse scene;
#    - scenes/vdb/fixtures/sparse-cloud.vdb kept sparse equals it read dense (sparse = "never"),
#      and equals BEFORE's sparse image;
#    - the CPU's image of the sparse bucky equals the GPU's.
# 2. Tiles: fill1024.vdb and fill4096.vdb render on the GPU within 60 s each (the GPU reads the
#    flat brick table, 512 MiB for fill4096); a 16384^3 box of 64 root tiles (written here from
#    fill4096.vdb, as volpt-scene/tests/vdb_tiles.rs does: 2^33 bricks, past the flat table's 2^28)
#    is refused by the GPU with the message that names the CPU, and renders on the CPU in 60 s.
# 3. A/B (`volpt bench` with AB_ARGS, by default `--strategy regeneration-sk --math fast`; AB_ARGS=
#    (empty) measures the defaults; TRIALS trials, rounds BEFORE/AFTER alternated
#    twice): the grey scenes with --bricked (the any-layout kernels the sparse lookup lives in:
#    smoke, bucky, cgg-logo), sparse bucky.vdb, and the large cloud kept sparse if
#    bundle/vdb-bench/large-cloud-*.vdb is there.
# Expected: every check line "PASS ..."; the last line "sparse-table: 0 failures"; in the A/B
# lines, AFTER (kernels without the two-level arm, session 12) faster than a BEFORE of sessions
# 8-11 on every scene (the --bricked ones through fewer registers, the sparse ones through one
# table read per corner instead of two).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
AB_ARGS=${AB_ARGS---strategy regeneration-sk --math fast}
BEFORE=${BEFORE:-$PWD/bin/volpt-before}
AFTER=${AFTER:-$PWD/bin/volpt}
for b in "$BEFORE" "$AFTER"; do
    [ -f "$b.gz" ] && gunzip -f "$b.gz"
    chmod +x "$b"
done
export VOLPT_CACHE_DIR=$OUT/cache
TRIALS=${TRIALS:-3}
SPP=${SPP:-100}
failures=0
log() { echo "== $*" | tee -a "$OUT/sparse-table.txt"; }
check() { # check NAME SECONDS CMD...: run under a time limit, record, count failures
    local name=$1 seconds=$2; shift 2
    if timeout "$seconds" "$@" >"$OUT/$name.log" 2>&1; then log "PASS $name: $(tail -n 1 "$OUT/$name.log")"
    else log "FAIL $name (exit $?): $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1)); fi
}
log "date $(date -u +%Y-%m-%dT%H:%MZ), $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -n 1)"
"$AFTER" scene generate scenes >/dev/null

# 1. Exact images.
COMMON=(--spp 4 --seed 7 --resolution 200x200)
GPU=(--backend cuda --strategy naive-sk --math exact)
dir=$(mktemp -d)
for mode in always never; do
    printf '[volume]\nfile = "%s"\nsparse = "%s"\nnormalise = 100\n[boundary]\nbsdf = "null"\n[camera]\nfov = 0.8\n' \
        "$PWD/scenes/vdb/fixtures/sparse-cloud.vdb" "$mode" >"$dir/cloud-$mode.toml"
done
check raw-gpu 300 "$AFTER" render scenes/bucky/scene.toml "${COMMON[@]}" "${GPU[@]}" -o "$OUT/raw-gpu.exr"
for v in after:"$AFTER" before:"$BEFORE"; do
    name=${v%%:*} bin=${v#*:}
    check "vdb-bucky-$name" 300 "$bin" render scenes/vdb/bucky.toml "${COMMON[@]}" "${GPU[@]}" -o "$OUT/vdb-bucky-$name.exr"
    check "cloud-sparse-$name" 300 "$bin" render "$dir/cloud-always.toml" "${COMMON[@]}" "${GPU[@]}" -o "$OUT/cloud-sparse-$name.exr"
done
check cloud-dense 300 "$AFTER" render "$dir/cloud-never.toml" "${COMMON[@]}" "${GPU[@]}" -o "$OUT/cloud-dense.exr"
check vdb-bucky-cpu 600 "$AFTER" render scenes/vdb/bucky.toml "${COMMON[@]}" -o "$OUT/vdb-bucky-cpu.exr"
check same-vdb-bucky-vs-raw 60 "$AFTER" compare "$OUT/raw-gpu.exr" "$OUT/vdb-bucky-after.exr" --identical
check same-vdb-bucky-vs-before 60 "$AFTER" compare "$OUT/vdb-bucky-before.exr" "$OUT/vdb-bucky-after.exr" --identical
check same-vdb-bucky-cpu-vs-gpu 60 "$AFTER" compare "$OUT/vdb-bucky-cpu.exr" "$OUT/vdb-bucky-after.exr" --identical
check same-cloud-sparse-vs-dense 60 "$AFTER" compare "$OUT/cloud-dense.exr" "$OUT/cloud-sparse-after.exr" --identical
check same-cloud-vs-before 60 "$AFTER" compare "$OUT/cloud-sparse-before.exr" "$OUT/cloud-sparse-after.exr" --identical

# 2. Tile-heavy files.
python3 - "$PWD/scenes/vdb/fixtures/fill4096.vdb" "$dir/fill16384.vdb" <<'EOF'
import struct, sys
b = open(sys.argv[1], "rb").read()
head, n = b[:-25], 4  # the root's tile and child counts and its one tile end the file
assert b[-25:-17] == struct.pack("<II", 1, 0)
out = bytearray(head + struct.pack("<II", n ** 3, 0))
for z in range(n):
    for y in range(n):
        for x in range(n):
            out += struct.pack("<iiifB", 4096 * x, 4096 * y, 4096 * z, 0.5, 1)
at = head.index(struct.pack("<q", len(b)))  # the grid's end offset: the file's length
out[at:at + 8] = struct.pack("<q", len(out))
open(sys.argv[2], "wb").write(out)
EOF
for f in scenes/vdb/fixtures/fill1024.vdb scenes/vdb/fixtures/fill4096.vdb; do
    check "$(basename "$f" .vdb)" 60 "$AFTER" render "$f" -Dresolution=48 --spp 4 --backend cuda -o "$OUT/$(basename "$f" .vdb).exr"
done
check fill16384-refused-by-gpu 60 bash -c 'if "$1" render "$2" -Dresolution=48 --spp 4 --backend cuda -o "$3" >"$4" 2>&1; then echo "rendered: a refusal was expected"; exit 1; fi; grep "render it on the CPU" "$4"' _ "$AFTER" "$dir/fill16384.vdb" "$OUT/fill16384-gpu.exr" "$OUT/fill16384-gpu.txt"
check fill16384-cpu 60 "$AFTER" render "$dir/fill16384.vdb" -Dresolution=48 --spp 4 -o "$OUT/fill16384-cpu.exr"

# 3. A/B.
SCENES=(
    "smoke-bricked:scenes/smoke/scene.xml:-Ddata=$PWD/data --bricked"
    "bucky-bricked:scenes/bucky/scene.toml:-Ddata=$PWD/data --bricked"
    "cgg-logo-bricked:scenes/cgg-logo/scene.xml:--bricked"
    "vdb-bucky-sparse:scenes/vdb/bucky.toml:"
)
cloud=$(ls vdb-bench/large-cloud-*.vdb 2>/dev/null | tail -n 1)
if [ -n "$cloud" ]; then
    printf '[volume]\nfile = "%s"\nsparse = "always"\nnormalise = 100\n[boundary]\nbsdf = "null"\n[camera]\nfov = 0.8\n' \
        "$PWD/$cloud" >"$dir/large.toml"
    SCENES+=("large-cloud-sparse:$dir/large.toml:")
fi
for entry in "${SCENES[@]}"; do
    IFS=: read -r name file params <<<"$entry"
    for round in 1 2; do
        for bin in "$BEFORE" "$AFTER"; do
            # shellcheck disable=SC2086
            if timeout 300 "$bin" bench "$file" $params --spp "$SPP" --backend cuda $AB_ARGS --trials "$TRIALS" --json >"$OUT/tmp.json" 2>"$OUT/tmp.log"; then
                python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(f\"AB {sys.argv[2]:<14} {sys.argv[3]:<20} round {sys.argv[4]} {r['time_median_s']*1e3:9.2f} ms  {r['paths_per_s']/1e6:8.2f} M paths/s\")" \
                    "$OUT/tmp.json" "$(basename "$bin")" "$name" "$round" | tee -a "$OUT/sparse-table.txt"
            else
                log "FAIL bench $(basename "$bin") $name: $(tail -n 2 "$OUT/tmp.log" | tr '\n' ' ')"
                failures=$((failures + 1))
            fi
        done
    done
done
rm -f "$OUT/tmp.json" "$OUT/tmp.log"
log "sparse-table: $failures failures"
