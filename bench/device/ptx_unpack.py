#!/usr/bin/env python3
"""Rebuild the PTX of chosen kernels from a `volpt` binary's embedded kernel packs, so that an old
binary's kernels can be compared (ptxas -v, ptx_diff.py) without rebuilding its commit.

  python3 bench/device/ptx_unpack.py BINARY REGEX OUT_PREFIX

writes OUT_PREFIX-<n>.ptx for each pack in BINARY (a build carries the exact and the fast one, in
that order): the pack's common text with every entry whose name matches REGEX put back where it
stood (volpt-cuda/src/kernels/layout.rs describes the pack). Needs the `zstd` command.
"""

import re
import subprocess
import sys

MAGIC = b"volptPK1"


def unzstd(data):
    return subprocess.run(["zstd", "-dc"], input=data, capture_output=True, check=True).stdout


def packs(binary):
    """(offset, index text) of each well-formed pack in `binary`."""
    found, at = [], binary.find(MAGIC)
    while at >= 0:
        length = int.from_bytes(binary[at + 8 : at + 16], "little")
        if 0 < length < 1 << 26:
            try:
                index = unzstd(binary[at + 16 : at + 16 + length]).decode()
                found.append((at + 16 + length, index))
            except subprocess.CalledProcessError:
                pass
        at = binary.find(MAGIC, at + 1)
    return found


def unpack(binary, frames_at, index, pattern):
    frames, entries, offset = [], [], frames_at
    for line in index.splitlines():
        record = line.split("\t")
        if record[0] == "frame":
            size = int(record[2])
            frames.append((offset, size))
            offset += size
        elif record[0] == "entry" and pattern.search(record[1]):
            entries.append((record[1], int(record[2]), int(record[3]), int(record[4]), int(record[5])))
    texts = {}

    def text(frame):
        if frame not in texts:
            start, size = frames[frame]
            texts[frame] = unzstd(binary[start : start + size]).decode()
        return texts[frame]

    common = text(0)
    # Entries go back in at their places, the last first, so that earlier places stay valid.
    out = common
    for name, frame, start, length, at in sorted(entries, key=lambda e: -e[4]):
        out = out[:at] + text(frame)[start : start + length] + out[at:]
    return out, [e[0] for e in entries]


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    binary = open(sys.argv[1], "rb").read()
    pattern = re.compile(sys.argv[2])
    found = packs(binary)
    if not found:
        sys.exit(f"{sys.argv[1]}: no kernel pack")
    for n, (frames_at, index) in enumerate(found):
        ptx, names = unpack(binary, frames_at, index, pattern)
        path = f"{sys.argv[3]}-{n}.ptx"
        open(path, "w").write(ptx)
        print(f"{path}: {len(names)} entries, {len(ptx)} bytes")


if __name__ == "__main__":
    main()
