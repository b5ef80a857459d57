#!/usr/bin/env bash
# 2026-11-27 (session 6), one H100, after the register cap of 64 became the default of a render
# too short for auto's calibration (`volpt::auto::DEFAULT`), on a machine where an earlier call
# unpacked the Mitsuba wheels: the session's final bundle (.dev/s8: as .dev/s7 with that binary)
# 1. bench/peers/mitsuba3/device.sh, MODE=gpu, all seven scenes;
# 2. thesis-efficiency.sh with volpt's GPU defaults (no --strategy; fast math, stochastic lookups).
#   OUT=$OUT bash bench/results/2026-11-27-h100-session6/call-defaults.sh
set -uo pipefail
ROOT=$PWD
B=$ROOT/.dev/s8
[ -f "$B/bin/volpt.gz" ] && gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
rm -rf bundle && ln -s .dev/s8 bundle
MODE=gpu timeout 400 bash bench/peers/mitsuba3/device.sh > "$OUT/mitsuba.log" 2>&1
grep "gpu |" "$OUT/mitsuba.log" | sed 's/^== //' | cut -c1-400
cd "$B"
MATH=fast LOOKUP=stochastic OUT=/tmp/te timeout 170 bash thesis-efficiency.sh > /dev/null 2>&1
cp /tmp/te/thesis-efficiency.txt "$OUT/thesis-efficiency.txt"; cat "$OUT/thesis-efficiency.txt"
