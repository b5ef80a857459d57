# 2026-11-24T22:5xZ, call A: the first look at the new strategies (selftest, small renders against the CPU, cgg-logo timings); bucky failed to load here (a relative -Ddata).
set -uo pipefail
cd bundle; gunzip -f bin/volpt.gz; chmod +x bin/volpt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
timeout 120 bin/volpt selftest 2>&1 | tail -25
bin/volpt scene generate scenes >/dev/null 2>&1
for sc in "cgg-logo:scenes/cgg-logo/scene.xml:" "cube-null:scenes/homogeneous-cube/scene.xml:-Dboundary=null" "bucky:scenes/bucky/scene.toml:-Ddata=data"; do
  IFS=: read -r name file params <<<"$sc"
  bin/volpt render $file $params -Dresolution=96 --spp 4 --seed 7 -o $OUT/$name-cpu.exr >/dev/null 2>&1 || echo "cpu fail $name"
  for s in naive-mk streaming-mk streaming-sorted-sk sorting-sk streaming-sk; do
    t0=$(date +%s.%N)
    if timeout 60 bin/volpt render $file $params -Dresolution=96 --spp 4 --seed 7 --backend cuda --strategy $s -o $OUT/$name-$s.exr > $OUT/$name-$s.log 2>&1; then
      echo "$name $s $(echo "$(date +%s.%N) - $t0" | bc) s: $(bin/volpt compare $OUT/$name-cpu.exr $OUT/$name-$s.exr --max-relative 1e-6 2>&1 | tail -1)"
    else echo "$name $s FAILED rc=$?: $(tail -3 $OUT/$name-$s.log)"; fi
  done
done
rm -f $OUT/*.exr $OUT/*.png
for s in regeneration-sk streaming-sk streaming-sorted-sk sorting-sk naive-mk streaming-mk; do
  timeout 60 bin/volpt bench scenes/cgg-logo/scene.xml --backend cuda --strategy $s --math fast --trials 2 2>&1 | grep -iE "median|paths/s|error" | head -3 | sed "s/^/$s: /"
done
