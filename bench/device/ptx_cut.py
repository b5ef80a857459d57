#!/usr/bin/env python3
"""PTX files cut down to some kernels, and what each kernel keeps in local memory.

    ptx_cut.py IN.ptx OUT.ptx REGEX   # OUT holds the module header, every .func and the .entry
                                      # points whose names REGEX matches (re.search)
    ptx_cut.py --stack IN.ptx         # one line per .entry: its local depot in bytes (0: none)

Cutting keeps ptxas fast and a bundle small (bench/ab/merge-regression.sh, strategies.sh). A local
depot is what LLVM could not keep in registers: an array indexed at run time, or an argument
taken by address by a call it did not inline; ptxas reports it as the stack frame.
"""
import re
import sys


def entries(lines):
    """(name, first line, last line) of every .entry, by its braces at column 0."""
    i = 0
    while i < len(lines):
        m = re.search(r"\.entry (\w+)", lines[i])
        if not m:
            i += 1
            continue
        j = i
        while lines[j] != "{":
            j += 1
        while lines[j] != "}":
            j += 1
        yield m.group(1), i, j
        i = j + 1


def cut(src, dst, pattern):
    keep = re.compile(pattern)
    lines = open(src).read().split("\n")
    out, last = [], 0
    for name, first, end in entries(lines):
        out.extend(lines[last:first])
        if keep.search(name):
            out.extend(lines[first:end + 1])
        last = end + 1
    out.extend(lines[last:])
    open(dst, "w").write("\n".join(out))
    return sum(1 for line in out if ".entry " in line)


def stack(src):
    lines = open(src).read().split("\n")
    for name, first, end in entries(lines):
        depot = 0
        for line in lines[first:end + 1]:
            m = re.search(r"__local_depot\d+\[(\d+)\]", line)
            if m:
                depot = int(m.group(1))
                break
        print(f"{depot:6} {name}")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--stack":
        stack(sys.argv[2])
    elif len(sys.argv) == 4:
        print(f"{sys.argv[2]}: {cut(*sys.argv[1:])} kernels")
    else:
        sys.exit(__doc__)
