#!/usr/bin/env bash
# Mutation testing with cargo-mutants (docs/testing.md records the runs and explains the survivors).
#
#   scripts/mutants.sh core [cargo-mutants options, e.g. --shard 0/8 --sharding round-robin]
#   scripts/mutants.sh loaders [cargo-mutants options]
#
# core: every mutant of volpt-core. The files volpt-core's own tests exercise (`units`: phase, BSDF,
# microfacet, Fresnel, frame, sampling, geometry, grid, tracking, math, RNG) are judged in two
# stages: stage `unit` runs volpt-core's tests (a mutant rebuilds one crate and ten small test
# binaries); the mutants it misses (and only those, by name) go to stage `unit-renderer`, judged by the whole-renderer tests that can see a core mutant: the
# independent references, the majorant checks and the launch-parameter round trip
# (tests/tests/references.rs, majorant.rs, device_abi.rs), which rebuild the render factory's
# variants. The files only the whole renderer exercises (camera, medium, environment, the path
# step, the device ABI, scene and variant plumbing) go to stage `renderer` directly. The unit and
# renderer stages take the cargo-mutants options, so `--shard k/n` names one sample of each. Results:
# target/mutants-core/{unit,unit-renderer,renderer}/mutants.out; a mutant of the units is caught
# if either of its stages caught it. STAGES (default "unit unit-renderer renderer") picks stages.
# loaders: the scene loaders (volpt-scene), judged by volpt-scene's tests.
#
# What makes a mutant cheap: the `mutants` profile (Cargo.toml) is the release profile,
# incremental and without debug info, so a mutant recompiles only the codegen units that
# instantiate the mutated function; the cheap judges run first and the expensive ones only on
# their survivors; the statistical suites that repeat what these check (analytic, stability,
# effects) are not run. A mutant that makes a test loop is stopped by the 120 s test timeout (the
# unmutated tests take ~20 s). Mutants that cannot change behaviour are excluded in
# .cargo/mutants.toml, each with its reason.
#
# The mutants are made in a copy of the checkout (target/mutants-tree, kept between runs so that
# builds stay incremental), never in the checkout itself, so one mutant runs at a time (--in-place
# excludes -j). On a shared machine, run it niced in the background and in shards:
#   nice -n 19 scripts/mutants.sh core --sharding round-robin --shard 0/8 > target/mutants.log 2>&1 &
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
version=27.1.0

scope=${1:?usage: scripts/mutants.sh core|loaders [cargo-mutants options]}
shift

if ! cargo mutants --version 2>/dev/null | grep -qF "$version"; then
    cargo install cargo-mutants --locked --version "$version"
fi

tree="$root/target/mutants-tree"
mkdir -p "$tree"
# Copy the sources (not target/ or .git) that differ from the previous copy, with a fresh mtime:
# unchanged files keep theirs (no needless rebuild), and a changed file is always newer than the
# builds of the previous run (copying with its own, older mtime once left a stale build "fresh").
(cd "$root" && git ls-files -co --exclude-standard -z | while IFS= read -r -d '' f; do
    cmp -s "$f" "$tree/$f" || cp --parents -t "$tree" "$f"
done)
cd "$tree"

mutants() {
    cargo mutants --in-place --no-shuffle --profile mutants --baseline skip \
        --timeout 120 --build-timeout 900 "$@"
}

case "$scope" in
core)
    out="$root/target/mutants-core"
    renderer_files='volpt-core/src/{camera,medium,environment,path,abi,scene,variant,lib}.rs'
    renderer_tests=(--test-package volpt-tests -- --test references --test majorant --test device_abi)
    for stage in ${STAGES:-unit unit-renderer renderer}; do
        echo "== stage $stage"
        mkdir -p "$out/$stage"
        # Exit status 2 means mutants survived, 3 timeouts: the next stage runs either way.
        case "$stage" in
        unit)
            mutants --package volpt-core --output "$out/unit" --exclude "$renderer_files" "$@" \
                --test-package volpt-core || true
            ;;
        unit-renderer)
            # Exactly the unit stage's survivors (its sample already), by name.
            filters=()
            while IFS= read -r name; do
                filters+=(-F "^$(printf '%s' "$name" | sed 's/[][\\.*+?(){}|^$]/\\&/g')\$")
            done < <(cat "$out/unit/mutants.out/missed.txt" "$out/unit/mutants.out/timeout.txt")
            if [ ${#filters[@]} -gt 0 ]; then
                mutants --package volpt-core --output "$out/unit-renderer" "${filters[@]}" \
                    "${renderer_tests[@]}" || true
            fi
            ;;
        renderer)
            mutants --package volpt-core --output "$out/renderer" --file "$renderer_files" "$@" \
                "${renderer_tests[@]}" || true
            ;;
        esac
    done
    ;;
loaders)
    mutants --package volpt-scene --output "$root/target/mutants-loaders" "$@" \
        --test-package volpt-scene
    ;;
*)
    echo "unknown scope $scope: core or loaders" >&2
    exit 2
    ;;
esac
