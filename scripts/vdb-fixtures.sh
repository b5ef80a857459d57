#!/usr/bin/env bash
# The VDB tests against fixtures written just now by the real OpenVDB library (issue 29): installs
# Debian's python3-openvdb where it is missing (as root, as volpt-view/browser-test.sh installs
# chromium), writes scenes/vdb/make_fixtures.py's files into target/vdb-fixtures, and runs the
# tests that read VDB files on them (VOLPT_VDB_FIXTURES). The committed copies in
# scenes/vdb/fixtures, which a plain `cargo test` reads, came from the same script.
#   scripts/vdb-fixtures.sh            # CI: .ci/run calls it
set -euo pipefail
cd "$(dirname "$0")/.."

if ! /usr/bin/python3 -c 'import pyopenvdb' 2>/dev/null; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-openvdb python3-numpy >/dev/null
fi
out=target/vdb-fixtures
rm -rf "$out"
/usr/bin/python3 scenes/vdb/make_fixtures.py "$out"
export VOLPT_VDB_FIXTURES=$PWD/$out
cargo test --release -q -p volpt-scene --test vdb --test vdb_sparse_memory
cargo test --release -q -p volpt --test vdb
echo "vdb-fixtures: the VDB tests pass on files OpenVDB wrote just now ($out)"
