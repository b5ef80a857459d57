#!/usr/bin/env bash
# Mutation testing with cargo-mutants (docs/testing.md records the runs and explains the survivors).
#
#   scripts/mutants.sh SCOPE [FILE...] [-- cargo-mutants options, e.g. --shard 0/2]
#
# SCOPE:
#   core     volpt-core, one file after another (the FILEs given, by default every file in the order
#            below), judged by volpt-core's own tests and the whole-renderer tests that can see a
#            core mutant: the independent references and the majorant checks
#            (tests/tests/references.rs, majorant.rs) and the launch-parameter round trip
#            (device_abi.rs). Results: target/mutants-core/<file>/mutants.out.
#   loaders  the scene loaders (volpt-scene), judged by volpt-scene's tests.
#
# What makes a mutant cheap (about 15-25 s here, against ~2 min with the release profile and every
# test binary): the `mutants` profile (Cargo.toml) is the release profile, incremental and without
# debug info, so a mutant recompiles only the codegen units that instantiate the mutated function;
# only the test binaries above are built and run (volpt-core's own tests in ~3 s, the references in
# ~13 s); the statistical suites that repeat what these check (analytic, stability, effects) are not
# run. A mutant that makes a test loop is stopped by the 60 s timeout (the unmutated tests take
# ~20 s). Mutants that cannot change behaviour are excluded in .cargo/mutants.toml, each with its
# reason.
#
# The mutants are made in a copy of the checkout (target/mutants-tree, kept between runs so that
# builds stay incremental), never in the checkout itself, so one mutant runs at a time (--in-place
# excludes -j). Run it niced in the background:
#   nice -n 19 scripts/mutants.sh core > target/mutants-core.log 2>&1 &
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
version=27.1.0

scope=${1:?usage: scripts/mutants.sh core|loaders [FILE...] [-- cargo-mutants options]}
shift
files=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    files+=("$1")
    shift
done
[ "${1:-}" = "--" ] && shift

if ! cargo mutants --version 2>/dev/null | grep -qF "$version"; then
    cargo install cargo-mutants --locked --version "$version"
fi

core=volpt-core/src
case "$scope" in
core)
    if [ ${#files[@]} -eq 0 ]; then
        # The renderer's path first (what the whole-renderer tests judge), then the units.
        for f in tracking path medium grid camera abi scene variant phase bsdf microfacet fresnel \
            geometry frame sampling environment rng math lib; do
            files+=("$core/$f.rs")
        done
    fi
    tests=(--test-package volpt-core --test-package volpt-tests --
        --lib --test bsdf --test fresnel --test geometry --test grid --test math --test microfacet
        --test phase --test rng --test tracking --test references --test majorant --test device_abi)
    ;;
loaders)
    [ ${#files[@]} -eq 0 ] && files=(volpt-scene/src/*.rs volpt-scene/src/mitsuba/*.rs)
    tests=(--test-package volpt-scene)
    ;;
*)
    echo "unknown scope $scope: core or loaders" >&2
    exit 2
    ;;
esac

tree="$root/target/mutants-tree"
mkdir -p "$tree"
# Copy the sources (not target/ or .git) over the previous copy; unchanged files keep their mtimes.
(cd "$root" && git ls-files -co --exclude-standard -z | xargs -0 cp --parents -p -t "$tree")

cd "$tree"
status=0
for f in "${files[@]}"; do
    out="$root/target/mutants-$scope/$(basename "$f" .rs)"
    mkdir -p "$out"
    echo "== $f -> $out/mutants.out"
    # Exit status 2 means mutants survived, 3 timeouts: record and go on to the next file.
    cargo mutants --in-place --no-shuffle --profile mutants --baseline skip \
        --timeout 60 --build-timeout 600 --output "$out" --file "$f" "$@" "${tests[@]}" || status=$?
done
exit "$status"
