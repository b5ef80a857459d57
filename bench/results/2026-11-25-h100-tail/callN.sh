# 2026-11-25, call N: the two racechecks call M cut at its 60 s limit (streaming-sorted-sk, sorting-sk;
# same command, 300 s), then auto-check.sh (fast math, 100 spp, 3 trials): auto against every fixed
# choice it could make, on the tail change's kernels.
set -uo pipefail
cd "$(dirname "$0")"
[ -f bin/volpt.gz ] && gunzip -f bin/volpt.gz; chmod +x bin/volpt
bin/volpt scene generate scenes > /dev/null
for s in streaming-sorted-sk sorting-sk; do
  /usr/bin/time -f "%e s" timeout 300 compute-sanitizer --tool racecheck --error-exitcode 1 bin/volpt render scenes/cgg-logo/scene.xml -Dresolution=32 --spp 1 --backend cuda --strategy $s -o /tmp/rc-$s.exr > /tmp/rc-$s.log 2>&1
  echo "racecheck-$s exit $?: $(grep 'RACECHECK SUMMARY' /tmp/rc-$s.log) $(tail -1 /tmp/rc-$s.log)" | tee -a $OUT/racecheck.txt
done
TRIALS=3 bash auto-check.sh > /dev/null 2>&1; echo "auto-check exit $?"
cat $OUT/auto-check.txt
