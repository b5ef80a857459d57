#!/usr/bin/env bash
# scripts/sync-tree.sh DIR: makes DIR a copy of the checkout's sources (not target/ or .git), for
# the mutation scripts, which mutate the copy and never the checkout. Only the files that differ
# from the previous copy are copied, with a fresh mtime: unchanged files keep theirs (no needless
# rebuild), and a changed file is always newer than the builds of the previous run (copying with
# its own, older mtime once left a stale build "fresh").
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
tree=${1:?usage: scripts/sync-tree.sh DIR}
mkdir -p "$tree"
cd "$root"
git ls-files -co --exclude-standard -z | while IFS= read -r -d '' f; do
    cmp -s "$f" "$tree/$f" || cp --parents -t "$tree" "$f"
done
