#!/usr/bin/env bash
# 2026-11-27 (session 5), one H100: the thesis's renderer built on the device from the sources that
# ../shared/peers/thesis/assemble.sh assembles (its build.sh with only the variants that
# thesis-efficiency.sh runs: cvr_thread_stats and cvr_norr_stats; the other `variant` lines
# removed), then thesis-efficiency.sh with volpt's GPU defaults (fast math, stochastic lookups) and
# with texture lookups, 400x400, 100 spp against each side's own 4096-spp image. volpt: main with
# the thesis's roulette rule in volpt's throughput (min(1, max(T) eta^2)). Carried as .dev/s6: the
# device bundle (bin/volpt gzipped), thesis/ (gen_scenes.py, xml/, textures/, Bucky.raw) and
# thesis-src/ (src, external, third_party, the trimmed build.sh).
#   OUT=$OUT bash bench/results/2026-11-27-h100-session5/call-thesis.sh
set -uo pipefail
ROOT=$PWD
B=$ROOT/.dev/s6
R=$OUT
[ -f "$B/bin/volpt.gz" ] && gunzip -f "$B/bin/volpt.gz"; chmod +x "$B/bin/volpt"
NVCC=$(command -v nvcc || echo /usr/local/cuda/bin/nvcc)
cd "$B/thesis-src"
start=$(date +%s)
CUDA_HOME=$(dirname "$(dirname "$NVCC")") bash build.sh > "$R/thesis-build.log" 2>&1
echo "thesis build: rc $? in $(( $(date +%s) - start )) s"; tail -n 3 "$R/thesis-build.log"
mkdir -p "$B/thesis/bin" && cp bin/cvr_* "$B/thesis/bin/" && tar cJf "$R/thesis-bin.tar.xz" bin
cd "$B"
for cfg in "fast stochastic" "fast texture"; do
    set -- $cfg
    MATH=$1 LOOKUP=$2 OUT=/tmp/te timeout 250 bash thesis-efficiency.sh > /dev/null 2>&1
    cp /tmp/te/thesis-efficiency.txt "$R/thesis-efficiency-$1-$2.txt"
    cat "$R/thesis-efficiency-$1-$2.txt"
done
