#!/usr/bin/env bash
# The scanner-format tests against fixtures written just now by the real tools (issue 42): installs
# numpy, pynrrd, tifffile and pydicom with pip where they are missing, writes
# scenes/scanners/make_fixtures.py's files into target/scanner-fixtures, and runs the tests that
# read them (VOLPT_SCANNER_FIXTURES). The committed copies in scenes/scanners/fixtures, which a
# plain `cargo test` reads, came from the same script.
#   scripts/scanner-fixtures.sh            # CI: .ci/run calls it
set -euo pipefail
cd "$(dirname "$0")/.."

python=${PYTHON:-python3}
if ! "$python" -c 'import numpy, nrrd, tifffile, pydicom' 2>/dev/null; then
    "$python" -m pip install -q numpy pynrrd tifffile pydicom
fi
out=target/scanner-fixtures
rm -rf "$out"
"$python" scenes/scanners/make_fixtures.py "$out"
export VOLPT_SCANNER_FIXTURES=$PWD/$out
cargo test --release -q -p volpt-scene --test scanners
cargo test --release -q -p volpt --test scanners
echo "scanner-fixtures: the NRRD, TIFF and DICOM tests pass on files pynrrd, tifffile and pydicom wrote just now ($out)"
