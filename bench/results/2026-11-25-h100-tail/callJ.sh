# 2026-11-25, call J: the launch's tail is the longest paths' time; fewer resident warps per SM make
# each warp's iteration faster. regeneration-sk fast with VOLPT_BLOCKS_PER_SM (an experiment's
# host-side override of the occupancy's 9 blocks of 128 threads), median of 5.
set -uo pipefail
cd "$(dirname "$0")"
gunzip -f bin/volpt.gz ab/*.ptx.gz; chmod +x bin/volpt
V=$PWD/bin/volpt; export VOLPT_PTX=$PWD/ab/2-after.ptx
$V scene generate scenes > /dev/null
run() { # name file params spp extra...
  local name=$1 file=$2 params=$3 spp=$4; shift 4
  timeout 60 $V bench $file $params --spp $spp --backend cuda --strategy regeneration-sk --math fast --trials 5 --json "$@" > /tmp/r.json 2>/tmp/r.log || { echo "FAIL $name $spp $*"; tail -3 /tmp/r.log; return; }
  python3 -c "import json,sys; r=json.load(open('/tmp/r.json')); print(f\"{sys.argv[1]:<18} spp {sys.argv[2]:>4} bps {sys.argv[3]:<4} {r['time_median_s']*1e3:9.2f} ms +- {r['time_std_s']*1e3:5.2f}  {r['paths']/1e6:7.2f} M paths {r['segments_per_s']/1e9:7.3f} G seg/s\")" $name $spp "${VOLPT_BLOCKS_PER_SM:-9}"
}
{
echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader)"
for b in 9 7 5 4 3 2; do
  export VOLPT_BLOCKS_PER_SM=$b
  run cube-null scenes/homogeneous-cube/scene.xml -Dboundary=null 100
  run cube-null scenes/homogeneous-cube/scene.xml -Dboundary=null 25
  run cube-rough scenes/homogeneous-cube/scene.xml "" 100
  run cgg-logo scenes/cgg-logo/scene.xml "" 100
  run smoke scenes/smoke/scene.xml -Ddata=$PWD/data 100
done
} | tee $OUT/blocks.txt
