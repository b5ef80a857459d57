#!/usr/bin/env bash
# 2026-11-27 (session 5), one H100: the `rng32` branch's kernels (pcg4d in 32-bit operations instead
# of SplitMix64's finaliser; bench/results/notes/rng32.md on that branch) against main's, one binary
# (main's bundle, .dev/s6) running each PTX through VOLPT_PTX, both cut to the regeneration-sk
# kernels by bench/device/ptx_cut.py (ab/1-main.ptx, ab/2-rng32.ptx, gzipped):
# 1. ab.sh twice: five scenes, regeneration-sk, fast math, defaults, median of 3;
# 2. a lone path on the index-matched cube (1x1 pixel, 1 spp; each RNG traces other paths, so the
#    pace is time / segments), seeds 1-8;
# 3. the two kernels' images of the index-matched cube as independent estimates (compare --independent).
#   OUT=$OUT bash bench/results/2026-11-27-h100-session5/call-rng32.sh
set -uo pipefail
cd .dev/s6
[ -f bin/volpt.gz ] && gunzip -f bin/volpt.gz; chmod +x bin/volpt
gunzip -f ab/*.ptx.gz
for r in 1 2; do OUT=/tmp/ab$r timeout 150 bash ab.sh > /dev/null 2>&1; cat /tmp/ab$r/ab.txt; done | tee "$OUT/ab-rng32.txt" | cut -c1-110
A="scenes/homogeneous-cube/scene.xml -Dboundary=null --backend cuda --strategy regeneration-sk"
for p in 1-main 2-rng32; do for s in 1 2 3 4 5 6 7 8; do
    VOLPT_PTX=ab/$p.ptx ./bin/volpt bench $A --resolution 1x1 --spp 1 --seed $s --trials 3 --json 2>/dev/null \
      | python3 -c "import json,sys; r=json.load(sys.stdin); t=r['time_median_s']*1e6; n=r['segments']; print(f'$p seed $s: {t:.1f} us, {n} segments, {t/max(n,1):.3f} us/segment')"
done; done | tee "$OUT/lone-rng32.txt"
VOLPT_PTX=ab/1-main.ptx ./bin/volpt render $A --resolution 64x64 --spp 1024 --seed 1 -o /tmp/m.exr > /dev/null 2>&1
VOLPT_PTX=ab/2-rng32.ptx ./bin/volpt render $A --resolution 64x64 --spp 1024 --seed 2 -o /tmp/r.exr > /dev/null 2>&1
./bin/volpt compare --independent /tmp/m.exr /tmp/r.exr 2>&1 | tee "$OUT/compare-rng32.txt"
