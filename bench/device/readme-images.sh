#!/usr/bin/env bash
# The README's images: the included scenes rendered on the GPU at a quality that shows the renderer.
# Run on the device machine from the bundle that `cargo xtask device-bundle` builds:
#
#   bash bundle/readme-images.sh             # PNGs and readme-images.txt under $OUT (default ./out)
#   SIZE=400 SPP_DIV=16 bash bundle/readme-images.sh   # a quick look: 400x400, 1/16 of the samples
#
# Writes $OUT/<name>.png for every scene below (the names README.md shows from docs/images/) and
# $OUT/readme-images.txt: the date, the device, and each render's command, time and summary. The
# EXRs stay in $WORK (they are large). Copy the PNGs to docs/images/ and commit them.
#
# Environment:
#   OUT, WORK   outputs (PNGs, log) and work files (EXRs, logs; default ./readme-work)
#   SIZE        pixels per side (default 800); SPP_DIV divides every scene's spp (default 1)
#   LIMIT       seconds per render (default 240)
#   DATA        a folder with smoke.vol (Mitsuba's grid) and Bucky.raw; default: the bundle's data/
#               where it has them, else each scene's own default (smoke: the generated stand-in;
#               bucky: scenes/bucky/Bucky.raw). The log's commands show which (-Ddata=...).
#   STRATEGY    default regeneration-sk: no calibration renders, the same choice every run
#   BACKEND     default cuda; cpu tries the script without a GPU
#   ONLY        names of the scenes to render (default all), e.g. ONLY="chromatic-cube chromatic-slab"
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
WORK=${WORK:-$PWD/readme-work}
SIZE=${SIZE:-800}
SPP_DIV=${SPP_DIV:-1}
LIMIT=${LIMIT:-240}
STRATEGY=${STRATEGY:-regeneration-sk}
BACKEND=${BACKEND:-cuda}
VOLPT=bin/volpt
mkdir -p "$OUT" "$WORK"
LOG=$OUT/readme-images.txt
say() { echo "$*" | tee -a "$LOG"; }

say "# README images, $(date -u +%Y-%m-%dT%H:%MZ)"
say "device: $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null | head -n 1)"
say "volpt: $($VOLPT --version 2>/dev/null)"
"$VOLPT" scene generate scenes >"$WORK/generate.log" 2>&1 || say "FAIL volpt scene generate: $(tail -n 2 "$WORK/generate.log")"

# -D data=DIR for the scenes that read third-party data, where a folder holds it.
data_param() { # data_param FILE: prints -Ddata=DIR if DIR/FILE exists
    local dir=${DATA:-$PWD/data}
    if [ -f "$dir/$1" ]; then echo "-Ddata=$dir"; fi
}

# name : scene file : samples per pixel (chosen so that the noise does not show at 800x800)
# : extra parameters. envmap-cube's small sun behind a rough dielectric needs the most samples.
SCENES=(
    "example-cube:scenes/example/cube.xml:4096:"
    "cgg-logo:scenes/cgg-logo/scene.xml:4096:"
    "ad:scenes/ad/scene.xml:4096:"
    "smoke:scenes/smoke/scene.xml:4096:$(data_param smoke.vol)"
    "bucky:scenes/bucky/scene.toml:4096:$(data_param Bucky.raw)"
    "envmap-cube:scenes/envmap-cube/scene.xml:16384:"
    "chromatic-cube:scenes/chromatic/cube.xml:4096:"
    "chromatic-slab:scenes/chromatic/slab.xml:4096:"
)

failures=0
for entry in "${SCENES[@]}"; do
    IFS=: read -r name file spp params <<<"$entry"
    [ -z "${ONLY:-}" ] || [[ " $ONLY " == *" $name "* ]] || continue
    spp=$((spp / SPP_DIV)); [ "$spp" -ge 1 ] || spp=1
    [ -f "$file" ] || { say "SKIP $name: $file not in this bundle"; continue; }
    cmd=("$VOLPT" render "$file" --backend "$BACKEND" --resolution "${SIZE}x${SIZE}" --spp "$spp"
        --seed 1 -o "$WORK/$name.exr")
    [ "$BACKEND" = cuda ] && cmd+=(--strategy "$STRATEGY")
    # shellcheck disable=SC2206
    [ -n "$params" ] && cmd+=($params)
    say ""
    say "\$ volpt ${cmd[*]:1}"
    t0=$(date +%s%N)
    if timeout "$LIMIT" "${cmd[@]}" >"$WORK/$name.log" 2>&1; then
        t1=$(date +%s%N)
        cp "$WORK/$name.png" "$OUT/$name.png"
        say "$name: $(((t1 - t0) / 1000000)) ms wall; $(sed 's/\x1b\[[0-9;]*m//g' "$WORK/$name.log" | grep 'paths/s' | tail -n 1)"
    else
        say "FAIL $name (exit $?): $(tail -n 3 "$WORK/$name.log" | tr '\n' ' ')"
        failures=$((failures + 1))
    fi
done
say ""
say "$failures failures"
exit $((failures > 0))
