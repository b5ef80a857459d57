#!/usr/bin/env bash
# Renders every included scene with two volpt binaries (e.g. before and after a refactor) on the CPU
# with the same seed and checks that the images are bit-identical.
#
#   bench/identity/cpu-before-after.sh OLD_VOLPT NEW_VOLPT [OUT_DIR]
#
# OLD_ARGS and NEW_ARGS (environment) add flags to each binary's renders, e.g.
# NEW_ARGS="--tracking global --estimator pt" to compare a new default against the old algorithm.
#
# Small films and few samples keep it quick; every scene's variant and every code path it uses
# (grids, maps, boundaries, roulette) still runs. Needs ../shared/data for smoke and bucky, and the
# generated grids and sky (`volpt scene generate`, run here with NEW).
set -uo pipefail
old=$1 new=$2 out=${3:-$(mktemp -d)}
cd "$(dirname "$0")/../.."
data=${DATA:-$PWD/../shared/data}
mkdir -p "$out"
"$new" scene generate scenes >/dev/null || exit 1
# name : scene file : extra parameters
scenes=(
    "example:scenes/example/cube.xml:"
    "homogeneous-cube:scenes/homogeneous-cube/scene.xml:"
    "homogeneous-cube-null:scenes/homogeneous-cube/scene.xml:-Dboundary=null"
    "cgg-logo:scenes/cgg-logo/scene.xml:"
    "ad:scenes/ad/scene.xml:"
    "smoke:scenes/smoke/scene.xml:-Ddata=$data"
    "smoke-mi3:scenes/smoke/scene-mi3.xml:-Ddata=$data"
    "bucky:scenes/bucky/scene.toml:-Ddata=$data"
    "envmap-cube:scenes/envmap-cube/scene.xml:"
)
failures=0
for entry in "${scenes[@]}"; do
    IFS=: read -r name file params <<<"$entry"
    for which in old new; do
        bin=${!which}
        args_var=${which^^}_ARGS
        # shellcheck disable=SC2086
        "$bin" render "$file" $params ${!args_var:-} --resolution 64x64 --spp 4 --seed 5 -o "$out/$name-$which.exr" \
            >"$out/$name-$which.log" 2>&1 || { echo "FAIL $name: $which render"; failures=$((failures + 1)); continue 2; }
    done
    if result=$("$new" compare "$out/$name-old.exr" "$out/$name-new.exr" --identical 2>&1); then
        echo "PASS $name: $(echo "$result" | tail -n 1)"
    else
        echo "FAIL $name: $result"; failures=$((failures + 1))
    fi
done
echo "$failures failures"
exit $((failures > 0))
