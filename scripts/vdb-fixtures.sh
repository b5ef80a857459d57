#!/usr/bin/env bash
# The VDB tests against fixtures written just now by the real OpenVDB library (issue 29): installs
# Debian's python3-openvdb where it is missing (as root, as volpt-view/browser-test.sh installs
# chromium; and libopenvdb-dev for the zip and uncompressed fixtures), writes
# scenes/vdb/make_fixtures.py's files into target/vdb-fixtures, and runs the
# tests that read VDB files on them (VOLPT_VDB_FIXTURES). The committed copies in
# scenes/vdb/fixtures, which a plain `cargo test` reads, came from the same script.
#   scripts/vdb-fixtures.sh            # CI: .ci/run calls it
set -euo pipefail
cd "$(dirname "$0")/.."

# The Python module writes most fixtures; OpenVDB's C++ headers (and Boost's, which they include)
# build scenes/vdb/recompress.cc for the zip and uncompressed ones.
if ! /usr/bin/python3 -c 'import pyopenvdb' 2>/dev/null || [[ ! -f /usr/include/openvdb/openvdb.h ]] \
    || [[ ! -d /usr/include/boost/numeric ]]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-openvdb python3-numpy \
        libopenvdb-dev libboost-dev g++ >/dev/null
fi
out=target/vdb-fixtures
rm -rf "$out"
/usr/bin/python3 scenes/vdb/make_fixtures.py "$out"
export VOLPT_VDB_FIXTURES=$PWD/$out
cargo test --release -q -p volpt-scene --test vdb --test vdb_sparse_memory
cargo test --release -q -p volpt --test vdb
echo "vdb-fixtures: the VDB tests pass on files OpenVDB wrote just now ($out)"
