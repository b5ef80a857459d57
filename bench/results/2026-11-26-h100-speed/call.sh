#!/usr/bin/env bash
# 2026-11-26, issue 25 "the next speed step" (branch speed2). Run from the repository root on the
# device: bash .dev/speed/call.sh. One binary (main's bundle, .dev/b/bin/volpt), kernels through
# VOLPT_PTX: base-* (main 442550b) and new-* (speed2), cut to the kernels used.
#  1. A/B: regeneration-sk, fast math, default lookups, 5 scenes, rounds base/new/base/new, median of 5
#  2. the index-matched cube at 25 spp and a lone path's pace (1x1, 1 spp, three seeds)
#  3. identity: new exact kernels, naive-sk --math exact against the CPU (bit for bit), 7 scenes
#  4. ncu: one launch of the index-matched cube (16 spp), base and new, a few metrics
set -uo pipefail
S=$PWD/.dev/speed; B=$PWD/.dev/b
W=/tmp/w; mkdir -p $W; cd $W
cp $B/bin/volpt.gz . && gunzip -f volpt.gz && chmod +x volpt
for f in $S/*.ptx.gz; do gunzip -c $f > $(basename $f .gz); done
V=$W/volpt
R=$B
$V scene generate $R/scenes > $W/generate.log 2>&1 || { echo "scene generate failed"; cat $W/generate.log; }
DATA=$B/data
ARCH=sm_$(nvidia-smi --query-gpu=compute_cap --format=csv,noheader | head -n 1 | tr -d '.')
for p in base-fast new-fast; do ptxas -arch=$ARCH -v $p.ptx -o /dev/null > $OUT/ptxas-$p.txt 2>&1 & done
SCENES=(
    "homogeneous-cube-null:$R/scenes/homogeneous-cube/scene.xml:-Dboundary=null"
    "homogeneous-cube:$R/scenes/homogeneous-cube/scene.xml:"
    "cgg-logo:$R/scenes/cgg-logo/scene.xml:"
    "smoke:$R/scenes/smoke/scene.xml:-Ddata=$DATA"
    "bucky:$R/scenes/bucky/scene.toml:-Ddata=$DATA"
)
row() { python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(f\"{sys.argv[2]:<10} {sys.argv[3]:<22} round {sys.argv[4]} {r['time_median_s']*1e3:9.2f} ms +- {r['time_std_s']*1e3:6.2f}  {r['segments_per_s']/1e9:7.3f} G seg/s  {r['segments']/r['paths']:6.1f} seg/path {r['tracking_steps']/r['paths']:6.1f} steps/path\")" "$@"; }
{
echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader) regeneration-sk fast, spp 100 (bucky 300), trials 5, medians"
for entry in "${SCENES[@]}"; do
    IFS=: read -r name file params <<<"$entry"
    spp=100; [ $name = bucky ] && spp=300
    for round in 1 2; do for p in base-fast new-fast; do
        VOLPT_PTX=$p.ptx timeout 90 $V bench $file $params --spp $spp --backend cuda --strategy regeneration-sk --math fast --trials 5 --json > r.json 2>r.log || { echo "FAIL $p $name"; tail -2 r.log; continue; }
        row r.json $p $name $round
    done; done
done
} 2>&1 | tee $OUT/ab.txt
{
for p in base-fast new-fast; do
    VOLPT_PTX=$p.ptx $V bench $R/scenes/homogeneous-cube/scene.xml -Dboundary=null --spp 25 --backend cuda --strategy regeneration-sk --math fast --trials 5 --json > r.json 2>/dev/null && row r.json $p cube-null-25spp 1
    for s in 1 15 21; do
        VOLPT_PTX=$p.ptx $V bench $R/scenes/homogeneous-cube/scene.xml -Dboundary=null --resolution 1x1 --spp 1 --seed $s --backend cuda --strategy regeneration-sk --math fast --trials 5 --json > r.json 2>/dev/null
        python3 -c "import json,sys; r=json.load(open('r.json')); print(f\"{sys.argv[1]:<10} lone path seed {sys.argv[2]:>2}: {r['segments']} segments {r['time_median_s']*1e3:.4f} ms\")" $p $s
    done
done
} 2>&1 | tee $OUT/tail.txt
ID=(
    "homogeneous-cube:$R/scenes/homogeneous-cube/scene.xml:-Dspp=100"
    "homogeneous-cube-null:$R/scenes/homogeneous-cube/scene.xml:-Dspp=100 -Dboundary=null"
    "cgg-logo:$R/scenes/cgg-logo/scene.xml:"
    "ad:$R/scenes/ad/scene.xml:"
    "smoke:$R/scenes/smoke/scene.xml:-Ddata=$DATA"
    "bucky:$R/scenes/bucky/scene.toml:-Ddata=$DATA"
    "envmap-cube:$R/scenes/envmap-cube/scene.xml:-Dspp=100 -Dresolution=400"
)
{
echo "# identity: CPU (main's binary) vs GPU naive-sk --math exact with new-exact.ptx, 4 spp, seed 7; regeneration-sk within 1e-6"
for entry in "${ID[@]}"; do
    IFS=: read -r name file params <<<"$entry"
    $V render $file $params --spp 4 --seed 7 -o $name-cpu.exr > /dev/null 2>&1 || { echo "FAIL $name cpu"; continue; }
    VOLPT_PTX=new-exact.ptx $V render $file $params --spp 4 --seed 7 --backend cuda --math exact --strategy naive-sk -o $name-gpu.exr > g.log 2>&1 || { echo "FAIL $name gpu"; tail -2 g.log; continue; }
    echo "$name naive-sk: $($V compare $name-cpu.exr $name-gpu.exr --identical 2>&1 | tail -1) rc=$?"
    VOLPT_PTX=new-exact.ptx $V render $file $params --spp 4 --seed 7 --backend cuda --math exact --strategy regeneration-sk -o $name-rg.exr > g.log 2>&1 || { echo "FAIL $name gpu rg"; continue; }
    echo "$name regeneration-sk: $($V compare $name-cpu.exr $name-rg.exr --max-relative 1e-6 2>&1 | tail -1)"
done
} 2>&1 | tee $OUT/identity.txt
M=smsp__inst_executed.sum,smsp__thread_inst_executed_per_inst_executed.ratio,gpu__time_duration.sum,smsp__issue_active.avg.pct_of_peak_sustained_active,sm__warps_active.avg.pct_of_peak_sustained_active,launch__registers_per_thread
for p in base-fast new-fast; do
  for sc in "cube-null:$R/scenes/homogeneous-cube/scene.xml:-Dboundary=null" "smoke:$R/scenes/smoke/scene.xml:-Ddata=$DATA"; do
    IFS=: read -r name file params <<<"$sc"
    echo "== $p $name"
    VOLPT_PTX=$p.ptx timeout 120 ncu --metrics $M -k regex:regeneration_sk --launch-count 1 $V render $file $params --spp 16 --backend cuda --strategy regeneration-sk --math fast -o x.exr 2>&1 | grep -E "regeneration_sk|smsp__|gpu__|sm__|launch__" | head -12
  done
done 2>&1 | tee $OUT/ncu.txt
wait
grep -h -A4 "regeneration_sk__homogeneous__index_matched__isotropic__constant'\|regeneration_sk__grid_density__index_matched__isotropic__constant'" $OUT/ptxas-*.txt > $OUT/ptxas-cube.txt 2>&1
