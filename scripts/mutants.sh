#!/usr/bin/env bash
# Mutation testing with cargo-mutants (docs/testing.md; bench/results/notes/mutation-testing.md records the runs and explains the survivors).
#
#   scripts/mutants.sh core [cargo-mutants options, e.g. --shard 3/8 --sharding round-robin]
#   scripts/mutants.sh loaders [cargo-mutants options]
#
# core: every mutant of volpt-core, judged in two stages. Stage `unit` runs volpt-core's own tests
# (a mutant rebuilds one crate and its small test binaries, ~7 s on an idle machine); the mutants
# it misses (and only those, by name) go to stage `unit-renderer`, judged by the whole-renderer
# tests that can see a core mutant: the independent references, the majorant checks and the
# launch-parameter round trip (tests/tests/references.rs, majorant.rs, device_abi.rs), which
# rebuild the render factory's variants (~1 min a mutant). Results:
# target/$OUT/{unit,unit-renderer}/mutants.out; a mutant is caught if either stage caught it.
# STAGES (default "unit unit-renderer") picks stages. (Until shard 2/8 of 2026-11-24 the files
# only the whole renderer exercised then, camera, medium, environment, path, abi, scene, went to a
# third stage judged by the renderer's tests alone; volpt-core has tests for each of them now.)
# loaders: the scene loaders (volpt-scene), judged by volpt-scene's tests.
#
# What makes a mutant cheap: the `mutants` profile (Cargo.toml) is the release profile,
# incremental and without debug info, so a mutant recompiles only the codegen units that
# instantiate the mutated function; the cheap judges run first and the expensive ones only on
# their survivors; the statistical suites that repeat what these check (analytic, stability,
# effects) are not run. A mutant that makes a test loop is stopped by the test timeout (60 s for
# volpt-core's tests, which take ~3 s; 120 s for the renderer's, ~20 s). Mutants that cannot
# change behaviour are excluded in .cargo/mutants.toml, each with its reason.
#
# The mutants are made in a copy of the checkout (target/$TREE, default mutants-tree, kept
# between runs so that builds stay incremental), never in the checkout itself, so one mutant runs
# at a time in a tree (--in-place excludes -j). Two runs go side by side in two trees, each with
# its own output (OUT, default mutants-core or mutants-loaders):
#   TREE=mutants-tree-b OUT=mutants-core-4 nice -n 19 scripts/mutants.sh core \
#       --sharding round-robin --shard 4/8 > target/mutants-4.log 2>&1 &
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

scope=${1:?usage: scripts/mutants.sh core|loaders [cargo-mutants options]}
shift

"$root/scripts/install-cargo-mutants.sh"

tree="$root/target/${TREE:-mutants-tree}"
"$root/scripts/sync-tree.sh" "$tree"
cd "$tree"

mutants() {
    cargo mutants --in-place --no-shuffle --profile mutants --baseline skip \
        --build-timeout 900 "$@"
}

case "$scope" in
core)
    out="$root/target/${OUT:-mutants-core}"
    for stage in ${STAGES:-unit unit-renderer}; do
        echo "== stage $stage"
        mkdir -p "$out/$stage"
        # Exit status 2 means mutants survived, 3 timeouts: the next stage runs either way.
        case "$stage" in
        unit)
            mutants --package volpt-core --output "$out/unit" --timeout 60 "$@" \
                --test-package volpt-core || true
            ;;
        unit-renderer)
            # Exactly the unit stage's survivors (its sample already), by name; its timeouts
            # are detected.
            filters=()
            while IFS= read -r name; do
                filters+=(-F "^$(printf '%s' "$name" | sed 's/[][\\.*+?(){}|^$]/\\&/g')\$")
            done <"$out/unit/mutants.out/missed.txt"
            if [ ${#filters[@]} -gt 0 ]; then
                mutants --package volpt-core --output "$out/unit-renderer" --timeout 120 \
                    "${filters[@]}" --test-package volpt-tests -- \
                    --test references --test majorant --test device_abi || true
            fi
            ;;
        *)
            echo "unknown stage $stage: unit or unit-renderer" >&2
            exit 2
            ;;
        esac
    done
    ;;
loaders)
    mutants --package volpt-scene --output "$root/target/${OUT:-mutants-loaders}" --timeout 120 \
        "$@" --test-package volpt-scene
    ;;
*)
    echo "unknown scope $scope: core or loaders" >&2
    exit 2
    ;;
esac
