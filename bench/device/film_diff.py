#!/usr/bin/env python3
"""The largest relative difference between the sums of two volpt film files (VOLPTFL1), with
their headers checked equal: `python3 film_diff.py A.vfilm B.vfilm [--max 1e-12]`.

Exits 1 when the films are of other renders or differ by more than --max (relative to
max(|a|, |b|, 1e-300)); prints how many sums are bit-identical."""
import struct
import sys


def read(path):
    data = open(path, "rb").read()
    if data[:8] != b"VOLPTFL1":
        sys.exit(f"{path}: not a VOLPTFL1 film")
    fingerprint, width, height, seed, count = struct.unpack_from("<QIIII", data, 8)
    ranges = [struct.unpack_from("<II", data, 32 + 8 * i) for i in range(count)]
    start = 32 + 8 * count
    sums = struct.unpack_from(f"<{3 * width * height}d", data, start)
    return (fingerprint, width, height, seed, ranges), sums


def main():
    args = sys.argv[1:]
    bound = 1e-12
    if "--max" in args:
        i = args.index("--max")
        bound = float(args[i + 1])
        del args[i : i + 2]
    (ha, a), (hb, b) = read(args[0]), read(args[1])
    if ha != hb:
        sys.exit(f"other renders: {ha} against {hb}")
    worst, same = 0.0, 0
    for x, y in zip(a, b):
        same += x == y
        worst = max(worst, abs(x - y) / max(abs(x), abs(y), 1e-300))
    print(f"{same} of {len(a)} sums bit-identical, largest relative difference {worst:.3e}")
    sys.exit(0 if worst <= bound else 1)


if __name__ == "__main__":
    main()
