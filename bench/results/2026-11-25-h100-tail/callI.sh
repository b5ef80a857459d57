# 2026-11-25, call I: how much of a render is its launch's tail? regeneration-sk fast (the HEAD kernels,
# 2-after.ptx), one launch per render at 25/50/100 spp (400x400), median of 5; a linear fit
# time = a * paths + b gives the tail's fixed cost b. Plus register caps on the index-matched cube.
set -uo pipefail
cd "$(dirname "$0")"
gunzip -f bin/volpt.gz ab/*.ptx.gz; chmod +x bin/volpt
V=$PWD/bin/volpt; export VOLPT_PTX=$PWD/ab/2-after.ptx
$V scene generate scenes > /dev/null
run() { # name file params spp extra...
  local name=$1 file=$2 params=$3 spp=$4; shift 4
  timeout 60 $V bench $file $params --spp $spp --backend cuda --strategy regeneration-sk --math fast --trials 5 --json "$@" > /tmp/r.json 2>/tmp/r.log || { echo "FAIL $name $spp $*"; tail -3 /tmp/r.log; return; }
  python3 -c "import json,sys; r=json.load(open('/tmp/r.json')); print(f\"{sys.argv[1]:<18} spp {sys.argv[2]:>4} {sys.argv[3]:<22} {r['time_median_s']*1e3:9.2f} ms +- {r['time_std_s']*1e3:5.2f}  {r['paths']/1e6:7.2f} M paths {r['segments_per_s']/1e9:7.3f} G seg/s\")" $name $spp "$*"
}
{
echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader)"
for spp in 25 50 100; do
  run cube-null scenes/homogeneous-cube/scene.xml -Dboundary=null $spp
  run cube-rough scenes/homogeneous-cube/scene.xml "" $spp
  run cgg-logo scenes/cgg-logo/scene.xml "" $spp
  run smoke scenes/smoke/scene.xml -Ddata=$PWD/data $spp
done
for r in 32 40 48 64; do run cube-null scenes/homogeneous-cube/scene.xml -Dboundary=null 100 --max-registers $r; done
} | tee $OUT/tail.txt
