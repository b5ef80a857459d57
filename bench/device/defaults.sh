#!/usr/bin/env bash
# Fastest correct by default (issue 25): the GPU's default configuration against the others, on
# the included scenes, in one device run.
# 1. identity: stochastic lookups (`--lookup stochastic`: one sample chosen by its trilinear
#    weight, on the GPU one unfiltered texel) render the CPU's image bit for bit with exact math
#    and naive-sk (every other strategy up to the order of its sums, 1e-6), and trilinear ones
#    still do: the stochastic texel fetch is exact, and the kernels' strategies agree;
# 2. parity at high sample counts: the new defaults (no --math, no --lookup), fast + stochastic
#    and fast + texture against exact + trilinear, each of its own seed, `volpt compare
#    --independent` (tile and whole-image z-tests);
# 3. time: `volpt bench`, regeneration-sk, each scene's spp, TRIALS after a warm-up: exact +
#    trilinear (the old defaults), fast + trilinear, fast + stochastic, fast + texture, exact +
#    stochastic; and the defaults with no flag at all (auto);
# 4. accuracy against time: `volpt converge --setting lookup=trilinear,stochastic,texture`, fast
#    math, TIME seconds per setting against a REFSPP reference;
# 5. start-up: a 16x16, 1-spp render's process time, warm (kernel in the driver's JIT cache),
#    and its parts, each printed line stamped (startup.py).
# 6. the defaults as shipped: the summary line of a render without flags, `--math exact` alone
#    against the CPU (bit for bit, naive-sk), and `volpt bench` without flags, with `--strategy
#    auto` and with fixed strategies (all with the default math and lookup).
#   bash bundle/defaults.sh   -> $OUT/defaults.txt, $OUT/converge-*.md
# Knobs: TRIALS (5), TIME (1.0), REFSPP (4096), PSPP (parity spp, 2048), PRES (parity
# resolution, 200), ONLY (scene regex), PARTS (default "1 2 3 4 5 6").
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
DATA=$PWD/data
TRIALS=${TRIALS:-5}
TIME=${TIME:-1.0}
REFSPP=${REFSPP:-4096}
PSPP=${PSPP:-2048}
PRES=${PRES:-200}
ONLY=${ONLY:-.}
PARTS=${PARTS:-1 2 3 4 5 6}
part() { [[ " $PARTS " == *" $1 "* ]]; }
WORK=$(mktemp -d "${TMPDIR:-/tmp}/defaults.XXXXXX")
export RUST_BACKTRACE=0 RUST_LIB_BACKTRACE=0 VOLPT_CACHE_DIR=$WORK/cache
first_error() { grep -m 2 -E "^Error|panicked|error" "$1" | tr '\n' ' '; }
"$VOLPT" scene generate scenes >/dev/null
# name : file : parameters : grids (1 if the medium has grids)
SCENES=(
    "homogeneous-cube:scenes/homogeneous-cube/scene.xml:-Dspp=100:0"
    "homogeneous-cube-null:scenes/homogeneous-cube/scene.xml:-Dspp=100 -Dboundary=null:0"
    "cgg-logo:scenes/cgg-logo/scene.xml::1"
    "ad:scenes/ad/scene.xml::1"
    "smoke:scenes/smoke/scene.xml:-Ddata=$DATA:1"
    "bucky:scenes/bucky/scene.toml:-Ddata=$DATA:1"
    "envmap-cube:scenes/envmap-cube/scene.xml:-Dspp=100 -Dresolution=400:0"
)
selected=()
for entry in "${SCENES[@]}"; do
    [[ ${entry%%:*} =~ $ONLY ]] && selected+=("$entry")
done
STRATEGIES="naive-sk naive-mk regeneration-sk regeneration-2p-sk regeneration-block-sk regeneration-warp-sk sorting-sk streaming-mk streaming-sk streaming-sorted-sk"
{
    echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv,noheader)"
    part 1 && {
    echo "## 1. identity (64x64, 4 spp, seed 7, exact math): CPU vs GPU"
    for entry in "${selected[@]}"; do
        IFS=: read -r name file params grids <<<"$entry"
        lookups=trilinear
        [ "$grids" = 1 ] && lookups="trilinear stochastic"
        strategies="naive-sk regeneration-sk"
        [ "$name" = cgg-logo ] && strategies=$STRATEGIES
        for lookup in $lookups; do
            common=(--resolution 64x64 --spp 4 --seed 7 --lookup "$lookup")
            # shellcheck disable=SC2086
            "$VOLPT" render "$file" $params "${common[@]}" -o "$WORK/$name-$lookup-cpu.exr" >/dev/null 2>&1
            for s in $strategies; do
                # shellcheck disable=SC2086
                timeout 60 "$VOLPT" render "$file" $params "${common[@]}" --backend cuda --math exact \
                    --strategy "$s" -o "$WORK/$name-$lookup-$s.exr" >/dev/null 2>"$WORK/r.log" \
                    || { echo "FAIL $name $lookup $s: $(first_error "$WORK/r.log")"; continue; }
                if [ "$s" = naive-sk ]; then tol=--identical; else tol="--max-relative 1e-6"; fi
                # shellcheck disable=SC2086
                if "$VOLPT" compare "$WORK/$name-$lookup-cpu.exr" "$WORK/$name-$lookup-$s.exr" $tol >"$WORK/c.txt" 2>&1; then
                    echo "PASS $name $lookup $s ($tol)"
                else
                    echo "FAIL $name $lookup $s ($tol): $(tail -n 1 "$WORK/c.txt")"
                fi
            done
        done
    done
    }
    part 2 && {
    echo "## 2. parity (${PRES}x${PRES}, $PSPP spp, regeneration-sk, independent seeds) against exact + trilinear"
    for entry in "${selected[@]}"; do
        IFS=: read -r name file params grids <<<"$entry"
        common=(--resolution "${PRES}x${PRES}" --spp "$PSPP" --backend cuda --strategy regeneration-sk)
        # shellcheck disable=SC2086
        timeout 120 "$VOLPT" render "$file" $params "${common[@]}" --math exact --lookup trilinear --seed 1 \
            -o "$WORK/p-$name-ref.exr" >/dev/null 2>"$WORK/r.log" \
            || { echo "FAIL $name reference: $(first_error "$WORK/r.log")"; continue; }
        configs="defaults:"
        [ "$grids" = 1 ] && configs="defaults: fast-stochastic:--math=fast,--lookup=stochastic fast-texture:--math=fast,--lookup=texture exact-stochastic:--math=exact,--lookup=stochastic"
        seed=1
        for config in $configs; do
            label=${config%%:*}
            flags=${config#*:}
            seed=$((seed + 1))
            # shellcheck disable=SC2086
            timeout 120 "$VOLPT" render "$file" $params "${common[@]}" ${flags//,/ } --seed "$seed" \
                -o "$WORK/p-$name-$label.exr" >"$WORK/r.out" 2>"$WORK/r.log" \
                || { echo "FAIL $name $label: $(first_error "$WORK/r.log")"; continue; }
            ran=$(grep -o "; [^)]*)" "$WORK/r.out" | head -n 1)
            if "$VOLPT" compare "$WORK/p-$name-ref.exr" "$WORK/p-$name-$label.exr" --independent >"$WORK/c.txt" 2>&1; then
                echo "PASS $name $label$ran: $(tail -n 1 "$WORK/c.txt")"
            else
                echo "FAIL $name $label$ran: $(tail -n 2 "$WORK/c.txt" | tr '\n' ' ')"
            fi
        done
    done
    }
    part 3 && {
    echo "## 3. time (400x400, each scene's spp, $TRIALS trials after a warm-up; medians)"
    for entry in "${selected[@]}"; do
        IFS=: read -r name file params grids <<<"$entry"
        configs="exact-trilinear:--strategy=regeneration-sk,--math=exact,--lookup=trilinear fast-trilinear:--strategy=regeneration-sk,--math=fast,--lookup=trilinear"
        [ "$grids" = 1 ] && configs="$configs fast-stochastic:--strategy=regeneration-sk,--math=fast,--lookup=stochastic fast-texture:--strategy=regeneration-sk,--math=fast,--lookup=texture exact-stochastic:--strategy=regeneration-sk,--math=exact,--lookup=stochastic"
        configs="$configs no-flags:"
        for config in $configs; do
            label=${config%%:*}
            flags=${config#*:}
            # shellcheck disable=SC2086
            timeout 120 "$VOLPT" bench "$file" $params --backend cuda ${flags//,/ } --trials "$TRIALS" --json \
                >"$WORK/b.json" 2>"$WORK/b.log" \
                || { echo "FAIL $name $label: $(first_error "$WORK/b.log")"; continue; }
            python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(f\"{sys.argv[2]:<22} {sys.argv[3]:<17} {r['time_median_s']*1e3:9.2f} ms  {r['segments_per_s']/1e9:7.3f} G seg/s  {r.get('strategy')} {r.get('math')}\")" \
                "$WORK/b.json" "$name" "$label"
        done
    done
    }
} 2>&1 | tee "$OUT/defaults.txt"
{
    part 4 && {
    echo "## 4. accuracy against time (converge, fast math, $TIME s per setting, reference $REFSPP spp)"
    for entry in "${selected[@]}"; do
        IFS=: read -r name file params grids <<<"$entry"
        [ "$grids" = 1 ] || continue
        # shellcheck disable=SC2086
        if timeout 150 "$VOLPT" converge "$file" $params --resolution 400x400 --backend cuda \
            --strategy regeneration-sk --reference-spp "$REFSPP" \
            --setting lookup=trilinear,stochastic,texture --setting math=fast --time "$TIME" \
            -o "$WORK/conv-$name" >"$WORK/conv.log" 2>&1; then
            echo "== $name"
            cat "$WORK/conv-$name/table.md"
            cp "$WORK/conv-$name/table.md" "$OUT/converge-$name.md"
            # Unbiased settings compare by variance alone, free of the reference's noise.
            python3 - "$WORK/conv-$name/converge.csv" <<'PY'
import csv, sys
last = {}
for row in csv.DictReader(open(sys.argv[1])):
    last[row["setting"]] = row
print("| setting | spp | time (s) | variance | bias | 1/(variance x time) |")
print("|---|---:|---:|---:|---:|---:|")
for name, r in last.items():
    v, t = float(r["variance"]), float(r["time_s"])
    print(f"| {name} | {r['spp']} | {t:.3f} | {v:.3e} | {float(r['bias']):.2e} | {1 / (v * t):.3e} |")
PY
        else
            echo "FAIL converge $name: $(first_error "$WORK/conv.log")"
        fi
    done
    }
    part 5 && {
    echo "## 5. start-up (scenes/example/cube.xml, 16x16, 1 spp, --backend cuda, no other flag)"
    OUT=$WORK python3 startup.py "$VOLPT" 5
    s=$(date +%s.%N); "$VOLPT" --version >/dev/null 2>&1; e=$(date +%s.%N)
    echo "volpt --version: $(python3 -c "print(f'{$e - $s:.3f}')") s"
    s=$(date +%s.%N); "$VOLPT" render scenes/example/cube.xml --resolution 16x16 --spp 1 -o "$WORK/tiny-cpu.exr" >/dev/null 2>&1; e=$(date +%s.%N)
    echo "the same render on the CPU: $(python3 -c "print(f'{$e - $s:.3f}')") s"
    }
    part 6 && {
    echo "## 6. the defaults as shipped: what a render without flags runs, --math exact alone, auto against fixed strategies"
    for entry in "${selected[@]}"; do
        IFS=: read -r name file params grids <<<"$entry"
        # shellcheck disable=SC2086
        "$VOLPT" render "$file" $params --backend cuda -o "$WORK/d-$name.exr" 2>/dev/null | grep -m 1 " spp (" | sed "s/^/$name: /"
        # --math exact alone: the CPU's image bit for bit (naive-sk).
        common=(--resolution 64x64 --spp 4 --seed 7)
        # shellcheck disable=SC2086
        "$VOLPT" render "$file" $params "${common[@]}" -o "$WORK/e-$name-cpu.exr" >/dev/null 2>&1
        # shellcheck disable=SC2086
        "$VOLPT" render "$file" $params "${common[@]}" --backend cuda --math exact --strategy naive-sk \
            -o "$WORK/e-$name-gpu.exr" >/dev/null 2>&1
        if "$VOLPT" compare "$WORK/e-$name-cpu.exr" "$WORK/e-$name-gpu.exr" --identical >"$WORK/c.txt" 2>&1; then
            echo "PASS $name: --math exact (naive-sk) is the CPU's image bit for bit"
        else
            echo "FAIL $name: --math exact (naive-sk) differs from the CPU: $(tail -n 1 "$WORK/c.txt")"
        fi
        for s in no-flags auto naive-sk regeneration-sk regeneration-warp-sk regeneration-block-sk streaming-sk sorting-sk; do
            flags=(--strategy "$s")
            [ "$s" = no-flags ] && flags=()
            # shellcheck disable=SC2086
            timeout 120 "$VOLPT" bench "$file" $params --backend cuda "${flags[@]}" --trials "$TRIALS" --json \
                >"$WORK/b.json" 2>"$WORK/b.log" \
                || { echo "FAIL $name $s: $(first_error "$WORK/b.log")"; continue; }
            python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(f\"{sys.argv[2]:<22} {sys.argv[3]:<22} {r['time_median_s']*1e3:9.2f} ms  {r['segments_per_s']/1e9:7.3f} G seg/s  {r.get('variant')}\")" \
                "$WORK/b.json" "$name" "$s"
        done
    done
    }
} 2>&1 | tee -a "$OUT/defaults.txt"
