# 2026-11-25, call F: where the index-matched cube's segment goes (the 40 G segments/s target):
# ncu --set full on one regeneration-sk launch (fast math, SPP=100 by default), details page, per-opcode
# instruction counts and the SASS with executed-instruction and stall counts.
set -uo pipefail
cd "$(dirname "$0")"
[ -f bin/volpt.gz ] && gunzip -f bin/volpt.gz; chmod +x bin/volpt
R=$OUT; W=/tmp/f; mkdir -p $W
bin/volpt scene generate scenes > /dev/null 2>&1
ARGS="scenes/homogeneous-cube/scene.xml -Dboundary=null -Dspp=${SPP:-100} --backend cuda --strategy regeneration-sk --math fast"
bin/volpt render $ARGS -o $W/a.exr 2>&1 | tail -2 | tee $R/render.txt
rm -f $W/p.ncu-rep; timeout 400 ncu -f --set full -k regex:regeneration_sk --launch-count 1 -o $W/p bin/volpt render $ARGS -o $W/b.exr > $W/ncu.log 2>&1; echo "ncu exit $?"
ncu --import $W/p.ncu-rep --page details > $R/details.txt 2>&1
ncu --import $W/p.ncu-rep --page source --csv --print-source sass > $W/sass.csv 2>&1
python3 - $W/sass.csv > $R/opcodes.txt <<'PY'
import csv, sys, collections
rows = list(csv.reader(open(sys.argv[1])))
hdr = next((i for i, r in enumerate(rows) if 'Source' in r), None)
if hdr is None: print('no header'); print(rows[:5]); sys.exit()
h = rows[hdr]; src = h.index('Source')
ex = next(i for i, c in enumerate(h) if c.startswith('Instructions Executed'))
st = next((i for i, c in enumerate(h) if c.startswith('Warp Stall Sampling (All')), None)
ops = collections.Counter(); stalls = collections.Counter(); total = 0; lines = []
for r in rows[hdr + 1:]:
    if len(r) <= ex: continue
    try: n = float(r[ex] or 0)
    except ValueError: continue
    op = r[src].strip().split()[0] if r[src].strip() else '?'
    if op.startswith('@'): op = r[src].strip().split()[1]
    op = op.split('.')[0]; ops[op] += n; total += n
    s = float(r[st] or 0) if st is not None else 0; stalls[op] += s
    lines.append((s, n, r[src].strip()))
print(f'total warp instructions executed {total:.0f}')
for op, n in ops.most_common(40): print(f'{op:<12} {n:14.0f} {100*n/total:6.2f}%  stall samples {stalls[op]:.0f}')
print('\nSASS lines with the most stall samples:')
for s, n, t in sorted(lines, reverse=True)[:40]: print(f'{s:8.0f} {n:12.0f}  {t}')
PY
gzip -c $W/sass.csv > $R/sass.csv.gz
head -5 $R/opcodes.txt; grep -E "Duration|Registers Per|Achieved Occupancy|Issue Slots Busy|Executed Ipc A|Warp Cycles Per Issued" $R/details.txt | head -12
