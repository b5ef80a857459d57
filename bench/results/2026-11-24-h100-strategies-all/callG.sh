# 2026-11-25, call G: sin_cos_2pi's quadrant by selects (after, bundlec/volpt.gz) against the match
# (before, bin/volpt: the final kernels otherwise), regeneration-sk fast, every scene, interleaved,
# median of 5; then naive-sk of the after binary against the CPU (bit-identical) on three scenes.
set -uo pipefail
cd "$(dirname "$0")"
[ -f bin/volpt.gz ] && gunzip -f bin/volpt.gz; chmod +x bin/volpt
gunzip -c ../bundlec/volpt.gz > bin/volpt-after; chmod +x bin/volpt-after
bin/volpt scene generate scenes > /dev/null 2>&1
SCENES=("cube-null:scenes/homogeneous-cube/scene.xml:-Dboundary=null" "cube:scenes/homogeneous-cube/scene.xml:" \
  "cgg-logo:scenes/cgg-logo/scene.xml:" "ad:scenes/ad/scene.xml:" "smoke:scenes/smoke/scene.xml:-Ddata=$PWD/data" \
  "bucky:scenes/bucky/scene.toml:-Ddata=$PWD/data" "envmap-cube:scenes/envmap-cube/scene.xml:-Dresolution=400")
for e in "${SCENES[@]}"; do IFS=: read -r name file params <<<"$e"
  for b in volpt volpt-after volpt volpt-after; do
    timeout 60 bin/$b bench $file $params -Dspp=100 --backend cuda --strategy regeneration-sk --math fast --trials 5 --json > /tmp/g.json 2>/dev/null \
     && python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(f\"{sys.argv[2]:<12} {sys.argv[3]:<12} {r['time_median_s']*1e3:9.2f} ms +- {r['time_std_s']*1e3:5.2f}  {r['segments_per_s']/1e9:7.3f} G seg/s\")" /tmp/g.json $name $b
  done
done | tee $OUT/ab-sincos.txt
for e in "${SCENES[@]:0:3}"; do IFS=: read -r name file params <<<"$e"
  bin/volpt-after render $file $params --spp 4 --seed 7 -o /tmp/$name-cpu.exr > /dev/null 2>&1
  bin/volpt-after render $file $params --spp 4 --seed 7 --backend cuda --strategy naive-sk -o /tmp/$name-gpu.exr > /dev/null 2>&1
  echo "$name naive-sk after vs CPU: $(bin/volpt-after compare /tmp/$name-cpu.exr /tmp/$name-gpu.exr --identical 2>&1 | tail -1)"
  bin/volpt render $file $params --spp 4 --seed 7 -o /tmp/$name-cpu-before.exr > /dev/null 2>&1
  echo "$name CPU after vs before: $(bin/volpt compare /tmp/$name-cpu.exr /tmp/$name-cpu-before.exr --identical 2>&1 | tail -1)"
done | tee -a $OUT/ab-sincos.txt
