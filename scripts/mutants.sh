#!/usr/bin/env bash
# Mutation testing with cargo-mutants (docs/testing.md records the runs and explains the survivors).
#
#   scripts/mutants.sh SCOPE [cargo-mutants options, e.g. --shard 0/2 --sharding round-robin]
#
# SCOPE:
#   renderer   camera, medium, tracking and the path step, judged by the whole-renderer tests
#              (tests/tests/references.rs and majorant.rs: the independent references)
#   core-units the rest of volpt-core, judged by volpt-core's own tests
#   loaders    the scene loaders (volpt-scene), judged by volpt-scene's tests
#
# The mutants are made in a copy of the checkout (target/mutants-tree, kept between runs so that
# only the mutated crates rebuild), never in the checkout itself; results go to target/mutants-SCOPE.
# One mutant builds and tests at a time: every mutant of volpt-core rebuilds the render factory's
# monomorphised variants, about two minutes on two busy cores, so scope runs with --file or --shard.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
version=27.1.0

scope=${1:?usage: scripts/mutants.sh renderer|core-units|loaders [cargo-mutants options]}
shift

if ! cargo mutants --version 2>/dev/null | grep -qF "$version"; then
    cargo install cargo-mutants --locked --version "$version"
fi

core=volpt-core/src
case "$scope" in
renderer)
    files=("$core/camera.rs" "$core/medium.rs" "$core/tracking.rs" "$core/path.rs")
    tests=(--test-package volpt-tests -- --test references --test majorant)
    ;;
core-units)
    files=()
    for f in "$core"/*.rs; do
        case "$f" in
        */camera.rs | */medium.rs | */tracking.rs | */path.rs | */lib.rs | */scene.rs | */launch.rs) ;;
        *) files+=("$f") ;;
        esac
    done
    tests=(--test-package volpt-core)
    ;;
loaders)
    files=(volpt-scene/src/*.rs volpt-scene/src/mitsuba/*.rs)
    tests=(--test-package volpt-scene)
    ;;
*)
    echo "unknown scope $scope: renderer, core-units or loaders" >&2
    exit 2
    ;;
esac

tree="$root/target/mutants-tree"
mkdir -p "$tree"
# Copy the sources (not target/ or .git) over the previous copy; unchanged files keep their mtimes.
(cd "$root" && git ls-files -co --exclude-standard -z | xargs -0 cp --parents -p -t "$tree")

file_args=()
for f in "${files[@]}"; do
    file_args+=(--file "$f")
done

cd "$tree"
cargo mutants --in-place --no-shuffle --profile release \
    --timeout 120 --build-timeout 600 \
    --output "$root/target/mutants-$scope" \
    "${file_args[@]}" "$@" "${tests[@]}"
