#!/usr/bin/env bash
# 2026-11-27 (session 6), one H100, after call-ab.sh on a machine where an earlier call unpacked the
# Mitsuba wheels: with the session's bundle (.dev/s7, as in call-ab.sh, plus thesis/ = the thesis's
# scenes and its binaries cvr_thread_stats/cvr_norr_stats built in session 5, bin.tar.xz):
# 1. bench/peers/mitsuba3/device.sh, MODE=gpu, the five scenes call-ab.sh did not run;
# 2. thesis-efficiency.sh with volpt's GPU defaults (fast math, stochastic lookups).
#   OUT=$OUT bash bench/results/2026-11-27-h100-session6/call-peers.sh
set -uo pipefail
ROOT=$PWD
B=$ROOT/.dev/s7
[ -f "$B/bin/volpt.gz" ] && gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
rm -rf bundle && ln -s .dev/s7 bundle
MODE=gpu SCENES="cgg-logo ad smoke bucky envmap-cube" timeout 330 bash bench/peers/mitsuba3/device.sh > "$OUT/mitsuba.log" 2>&1
cut -c1-400 "$OUT/peers/results.md" 2>/dev/null
cd "$B"
MATH=fast LOOKUP=stochastic OUT=/tmp/te timeout 240 bash thesis-efficiency.sh > /dev/null 2>&1
cp /tmp/te/thesis-efficiency.txt "$OUT/thesis-efficiency.txt"; cat "$OUT/thesis-efficiency.txt"
