# 2026-11-25, call L: the launch's tail is the pace of its last, longest paths (0.62 us a segment for a
# lone path, call K). A/B through VOLPT_PTX, one binary, fast math, median of 5, ab.sh's five scenes:
#   2-after     HEAD's kernels
#   3-exitdist  the free flight computes only the exit distance (the face only on escape); fast
#               math's approximations flush subnormals (.ftz: no scaling around rcp/div/lg2/sqrt)
#   4-drained   also: once the launch's paths are handed out, the warp skips the refill's votes
# plus the index-matched cube at 25 spp and a lone path's pace (1x1 pixel, 1 spp, three seeds).
set -uo pipefail
cd "$(dirname "$0")"
gunzip -f bin/volpt.gz ab/*.ptx.gz; chmod +x bin/volpt
TRIALS=5 STRATEGIES="regeneration-sk" bash ab.sh > /dev/null 2>&1
cat $OUT/ab.txt
V=$PWD/bin/volpt
for ptx in ab/*.ptx; do
  for spp in 25; do
    VOLPT_PTX=$ptx $V bench scenes/homogeneous-cube/scene.xml -Dboundary=null --spp $spp --backend cuda --strategy regeneration-sk --math fast --trials 5 --json > /tmp/r.json 2>/dev/null
    python3 -c "import json,sys; r=json.load(open('/tmp/r.json')); print(f\"{sys.argv[1]:<14} cube-null spp 25 {r['time_median_s']*1e3:8.2f} ms +- {r['time_std_s']*1e3:5.2f}\")" $(basename $ptx .ptx)
  done
  for s in 1 15 21; do
    VOLPT_PTX=$ptx $V bench scenes/homogeneous-cube/scene.xml -Dboundary=null --resolution 1x1 --spp 1 --seed $s --backend cuda --strategy regeneration-sk --math fast --trials 5 --json > /tmp/r.json 2>/dev/null
    python3 -c "import json,sys; r=json.load(open('/tmp/r.json')); print(f\"{sys.argv[1]:<14} lone path seed {sys.argv[2]:>2}: {r['segments']} segments {r['time_median_s']*1e3:.4f} ms\")" $(basename $ptx .ptx) $s
  done
done | tee $OUT/tail-ab.txt
