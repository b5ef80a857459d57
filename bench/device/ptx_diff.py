#!/usr/bin/env python3
"""Per-kernel comparison of two PTX modules (before and after a change), on the CPU.

    ptx_diff.py BEFORE.ptx AFTER.ptx [SHOW] [OLD=NEW ...]

SHOW: list that many differing kernels per strategy. OLD=NEW: compare BEFORE's kernels of entry
prefix OLD with AFTER's of prefix NEW (a kernel function renamed or shared).

Per strategy (the entry name's prefix): how many kernels are textually identical, and for those
that differ the change of their instruction count, virtual registers declared (`.reg` counts, an
upper bound of what ptxas allocates, not its figure) and local depot in bytes. Symbols' crate
hashes and module-wide numbering are ignored. ptxas's physical
register counts need the device machine (strategies.sh's ptxas reports).
"""
import collections
import re
import sys

from ptx_cut import entries


def kernels(path):
    text = open(path).read()
    # Names numbered or hashed module-wide, which differ when another kernel of the module changes
    # (or one is added before it) or the checkout moves: other crates' symbols carry a hash of the crate's path (`Cs<hash>_`),
    # constants an `anon_$_<hash>`, and local depots, call sequences, switch tables and basic-block
    # labels (`$L__BB<function>_<block>`) a counter.
    for pattern, by in [(r"Cs[0-9A-Za-z]+_(?=[0-9])", "Cs_"), (r"anon_\$_[0-9a-f]+_\$_", "anon_$_"),
                        (r"__local_depot\d+", "__local_depot"), (r"callseq \d+", "callseq"),
                        (r"(switch_\$_table_\$_\w+?)\d+\b", r"\1"), (r"\$L__BB\d+_", "$L__BB_")]:
        text = re.sub(pattern, by, text)
    lines = text.split("\n")
    return {name: lines[first:end + 1] for name, first, end in entries(lines)}


def stats(body):
    regs = sum(int(m.group(1)) for l in body for m in [re.search(r"\.reg \.\w+ \t?%\w+<(\d+)>", l)] if m)
    depot = max([int(m.group(1)) for l in body for m in [re.search(r"__local_depot\d*\[(\d+)\]", l)] if m] or [0])
    inst = sum(1 for l in body if l.startswith("\t") and l.strip().endswith(";") and not l.strip().startswith("."))
    return inst, regs, depot


before, after = kernels(sys.argv[1]), kernels(sys.argv[2])
print(f"# {sys.argv[1]}: {len(before)} kernels; {sys.argv[2]}: {len(after)} kernels")
show = int(sys.argv[3]) if len(sys.argv) > 3 and "=" not in sys.argv[3] else 0
for arg in sys.argv[3:]:
    if "=" in arg:
        old, new = arg.split("=")
        for name in [n for n in before if n.startswith(old + "__")]:
            renamed = new + name[len(old):]
            if renamed in after:
                after[name] = after[renamed]
renamed = {a.split("=")[1] for a in sys.argv[3:] if "=" in a}
missing = sorted(n for n in set(before) ^ set(after) if n.split("__")[0] not in renamed)
if missing:
    print(f"only in one module: {missing[:10]} ({len(missing)})")
by = collections.defaultdict(list)
for name in sorted(set(before) & set(after)):
    by[name.split("__")[0]].append(name)
for strategy, names in by.items():
    same = [n for n in names if before[n] == after[n]]
    diffs = []
    for n in names:
        if before[n] == after[n]:
            continue
        b, a = stats(before[n]), stats(after[n])
        diffs.append((n, b, a))
    line = f"{strategy:<24} {len(same):4}/{len(names):<4} identical"
    if diffs:
        d_inst = [a[0] - b[0] for _, b, a in diffs]
        d_regs = [a[1] - b[1] for _, b, a in diffs]
        d_depot = [a[2] - b[2] for _, b, a in diffs]
        line += (f"; differing: instructions {min(d_inst):+}..{max(d_inst):+} "
                 f"(mean {sum(d_inst) / len(diffs):+.1f} of {sum(b[0] for _, b, _ in diffs) / len(diffs):.0f}), "
                 f"virtual regs {min(d_regs):+}..{max(d_regs):+}, local depot {min(d_depot):+}..{max(d_depot):+} bytes")
    print(line)
    for n, b, a in diffs[:show]:
        print(f"    {n}: inst {b[0]} -> {a[0]}, regs {b[1]} -> {a[1]}, depot {b[2]} -> {a[2]}")
