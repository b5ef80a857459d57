#!/usr/bin/env bash
# Mutants of volpt-core's GPU-only code, judged on the GPU (bench/results/notes/mutation-testing.md, "GPU-only mutants").
#
#   scripts/gpu-mutants.sh                  # here: bundle-mutants/, one selftest PTX per mutant
#   cargo xtask device-bundle               # bundle/ with bin/volpt and bench/device/gpu-mutants.sh
#   # on the device, carrying bundle and bundle-mutants:
#   bash bundle/gpu-mutants.sh bundle-mutants
#
# The `core` scope of scripts/mutants.sh judges with CPU tests, and the code under
# `cfg(target_arch = "nvptx64")` (the fast kernels' approximate math, the texture fetch) is
# compiled by no CPU build: its mutants survive there whatever the tests. The functions that hold
# such code are listed below (FUNCTIONS, a regular expression over cargo-mutants' names); each
# of their mutants is applied to a copy of the tree (cargo-mutants' own diff), the selftest
# kernels are built with it (`cargo xtask ptx-selftests`: fast math, a minute instead of the full
# kernels' build), and the device script runs `volpt selftest` on each: a mutant is caught when a
# selftest fails. The unmutated build goes first and must pass. Mutants of these functions that
# change CPU code too are judged here as well (they are also judged by the CPU tests); a mutant
# whose selftest PTX is byte for byte the unmutated one (it mutates the CPU's side of a cfg) is
# reported as unreached, for the CPU tests to judge.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/${OUT:-bundle-mutants}"
tree="$root/target/${TREE:-gpu-mutants-tree}"
FUNCTIONS=${FUNCTIONS:-'^volpt-core/src/(math\.rs:.*(replace (sqrt|ln|exp|div|recip|approx::\w+) ->| in (ln|exp|div|recip|approx::\w+)$)|grid\.rs:.*(TextureTrilinear>::lookup|texture_fetch))'}

"$root/scripts/install-cargo-mutants.sh"
"$root/scripts/sync-tree.sh" "$tree"
cd "$tree"

rm -rf "$out"
mkdir -p "$out"
cargo mutants --package volpt-core --list --json --diff \
    --file volpt-core/src/math.rs --file volpt-core/src/grid.rs >"$out/all.json"
python3 - "$out" "$FUNCTIONS" <<'EOF'
import json, re, sys
out, pattern = sys.argv[1], re.compile(sys.argv[2])
chosen = [m for m in json.load(open(f"{out}/all.json")) if pattern.search(m["name"])]
with open(f"{out}/mutants.txt", "w") as names:
    for i, m in enumerate(chosen):
        with open(f"{out}/{i:03}.diff", "w") as diff:
            diff.write(m["diff"])
        names.write(f"{i:03} {m['file']} {m['name']}\n")
print(f"{len(chosen)} mutants of GPU-only code", file=sys.stderr)
EOF
rm "$out/all.json"

cargo xtask ptx-selftests "$out/baseline"
while read -r id file name; do
    echo "== $id $name"
    patch --quiet "$file" "$out/$id.diff"
    if cargo xtask ptx-selftests "$out/$id" >"$out/$id.log" 2>&1; then
        rm "$out/$id.log"
        # A mutant of a branch the fast kernels do not compile (the CPU's and the exact
        # kernels' side of a cfg) leaves their PTX as it was: the CPU tests judge it.
        if cmp -s "$out/$id/selftests_fast.ptx" "$out/baseline/selftests_fast.ptx"; then
            touch "$out/$id/unreached"
            echo "unreached: the fast kernels' PTX is unchanged"
        fi
    else
        echo "unviable: the selftest kernels do not build (see $id.log)"
    fi
    patch --quiet --reverse "$file" "$out/$id.diff"
done <"$out/mutants.txt"
git -C "$root" diff --quiet --no-index -- "$root/volpt-core/src" "$tree/volpt-core/src" ||
    { echo "the tree was not restored" >&2; exit 1; }
echo "ready: $out ($(wc -l <"$out/mutants.txt") mutants)"
