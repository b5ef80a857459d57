#!/usr/bin/env bash
# Judges the mutants of volpt-core's GPU-only code that scripts/gpu-mutants.sh built (one
# selftest PTX each, in DIR): `volpt selftest` with each PTX (`VOLPT_PTX`); a mutant is caught
# when a selftest fails, missed when all pass, unreached when its PTX is the unmutated one (a
# mutant of the CPU's side of a cfg, which the CPU tests judge). The unmutated build
# (DIR/baseline) must pass first, and so must the bundle's own exact and fast kernels.
#   bash bundle/gpu-mutants.sh bundle-mutants   -> $OUT/gpu-mutants.txt, $OUT/gpu-mutants.log
set -uo pipefail
dir=$(cd "${1:?usage: gpu-mutants.sh DIR}" && pwd)
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
summary=$OUT/gpu-mutants.txt
log=$OUT/gpu-mutants.log
: >"$log"
say() { echo "$*" | tee -a "$summary"; }
say "date $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader)"
for math in exact fast; do
    if "$VOLPT" selftest --math "$math" >>"$log" 2>&1; then
        say "PASS the bundle's $math kernels"
    else
        say "FAIL the bundle's $math kernels: the judge itself fails"
    fi
done
grep -E "math functions|^     " "$log" | sed -n '1,200p' >>"$summary"
if VOLPT_PTX="$dir/baseline/selftests_fast.ptx" "$VOLPT" selftest --math fast >>"$log" 2>&1; then
    say "PASS baseline (unmutated selftest kernels)"
else
    say "FAIL baseline: the unmutated selftest kernels fail, so no mutant can be judged"
    exit 1
fi
caught=0 missed=0 unviable=0 unreached=0
while read -r id file name; do
    ptx="$dir/$id/selftests_fast.ptx"
    if [ ! -f "$ptx" ]; then
        say "unviable $name"
        unviable=$((unviable + 1))
        continue
    fi
    if [ -f "$dir/$id/unreached" ]; then
        say "unreached $name"
        unreached=$((unreached + 1))
        continue
    fi
    timeout 120 env VOLPT_PTX="$ptx" "$VOLPT" selftest --math fast >"$OUT/one.log" 2>&1
    status=$?
    { echo "== $id $name (exit $status)"; cat "$OUT/one.log"; } >>"$log"
    if [ "$status" -eq 0 ]; then
        say "missed   $name"
        missed=$((missed + 1))
    else
        # What failed: the first failing selftest, or the error (a launch that faulted, say).
        say "caught   $name: $(grep -m 1 -oE '^FAIL [^:]+|^Error.*' "$OUT/one.log" || echo "exit $status")"
        caught=$((caught + 1))
    fi
done <"$dir/mutants.txt"
rm -f "$OUT/one.log"
say "GPU-only mutants: $caught caught, $missed missed, $unviable unviable, $unreached unreached"
