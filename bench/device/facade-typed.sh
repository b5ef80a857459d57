#!/usr/bin/env bash
# Issue 44 (part 3) on the GPU: the typed checks of the GPU options refuse what they must and
# nothing else, in the flags' words, and the facade still renders the CPU's bits. From the
# repository root, with a `volpt` built with the kernels (no cargo needed):
#
#   VOLPT=target/release/volpt bash bench/device/facade-typed.sh
#
# Expected (about 20 s on an H200): six "PASS" lines and "facade-typed: 0 failures".
set -uo pipefail
cd "$(dirname "$0")/../.."
VOLPT=${VOLPT:-target/release/volpt}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene=scenes/example/cube.xml
small=(--resolution 64x64 --spp 4 --seed 3)
failures=0
pass() { echo "PASS $1"; }
fail() { echo "FAIL $1: $2"; failures=$((failures + 1)); }
# renders NAME ARGS...: the render succeeds
renders() {
    local name=$1; shift
    if out=$("$VOLPT" render "$scene" "${small[@]}" --backend cuda "$@" -o "$work/$name.exr" 2>&1); then
        pass "$name"
    else fail "$name" "$(tail -n 2 <<<"$out")"; fi
}
# refuses NAME WORDS ARGS...: the render fails, saying WORDS
refuses() {
    local name=$1 words=$2; shift 2
    if out=$("$VOLPT" render "$scene" "${small[@]}" --backend cuda "$@" -o "$work/$name.exr" 2>&1); then
        fail "$name" "rendered"
    elif grep -qF -- "$words" <<<"$out"; then pass "$name"
    else fail "$name" "$(tail -n 2 <<<"$out")"; fi
}
renders knobs --strategy regeneration-sk --max-registers 64 --refill-at 8 --tiles 2,2
renders implicit-regeneration --refill-at 8
renders all-gpus --gpus all --strategy naive-sk
refuses tiles-with-auto "--tiles 2,2 with --strategy auto: auto chooses the strategy" --strategy auto --tiles 2,2
refuses no-such-gpu "--gpus: expected GPUs numbered 0 to" --gpus 0,63
"$VOLPT" render "$scene" "${small[@]}" --backend cpu -o "$work/cpu.exr" >/dev/null 2>&1
"$VOLPT" render "$scene" "${small[@]}" --backend cuda --strategy naive-sk --math exact -o "$work/exact.exr" >/dev/null 2>&1
if "$VOLPT" compare "$work/cpu.exr" "$work/exact.exr" --identical >/dev/null 2>&1; then pass exact-equals-cpu
else fail exact-equals-cpu "naive-sk exact differs from the CPU"; fi
echo "facade-typed: $failures failures"
exit $((failures > 0))
