# 2026-11-25, call K: the tail's pace. One warp alone (1x1 pixel, 1 sample: one path in one lane) on
# the index-matched cube, regeneration-sk fast: time and segments per seed; then ncu --set full on
# the slowest seed's launch, with the SASS's stall samples (what a lone warp waits on).
set -uo pipefail
cd "$(dirname "$0")"
gunzip -f bin/volpt.gz ab/*.ptx.gz; chmod +x bin/volpt
V=$PWD/bin/volpt; export VOLPT_PTX=$PWD/ab/2-after.ptx
R=$OUT; W=/tmp/k; mkdir -p $W
$V scene generate scenes > /dev/null
ARGS="scenes/homogeneous-cube/scene.xml -Dboundary=null --resolution 1x1 --spp 1 --backend cuda --strategy regeneration-sk --math fast"
best=1; bt=0
for s in $(seq 1 40); do
  $V bench $ARGS --seed $s --trials 3 --json > $W/r.json 2>/dev/null || { echo "FAIL seed $s"; continue; }
  line=$(python3 -c "import json; r=json.load(open('$W/r.json')); print(f\"{r['time_median_s']*1e3:.3f} {r['segments']/r['paths']:.1f} {r['segments']}\")")
  echo "seed $s: ms, segments/path, segments: $line" | tee -a $R/lone.txt
  t=$(echo $line | cut -d' ' -f1); if python3 -c "import sys; sys.exit(0 if $t > $bt else 1)"; then bt=$t; best=$s; fi
done
echo "slowest seed $best ($bt ms)" | tee -a $R/lone.txt
timeout 300 ncu -f --set full -k regex:regeneration_sk --launch-count 1 -o $W/p $V render $ARGS --seed $best -o $W/b.exr > $W/ncu.log 2>&1; echo "ncu exit $?"
tail -3 $W/ncu.log
ncu --import $W/p.ncu-rep --page details > $R/details.txt 2>&1
ncu --import $W/p.ncu-rep --page source --csv --print-source sass > $W/sass.csv 2>&1
gzip -c $W/sass.csv > $R/sass.csv.gz
grep -E "Duration|Warp Cycles Per Issued|Executed Ipc|SM Frequency" $R/details.txt | head
