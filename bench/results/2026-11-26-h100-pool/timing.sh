#!/bin/bash
# The before (main b2d71e4) and after (pool) trees' `cargo xtask ptx` from an empty PTX target
# directory, started together so that both see the same load.
for t in before after; do
  ( cd /tmp/wt-$t && rm -rf target-ptx && /usr/bin/time -f "$t: %e s wall, %U s user, %S s sys, %M KB max RSS" target/debug/xtask ptx > /tmp/timing-$t.log 2>&1 ) &
done
uptime; wait; uptime
grep -h "wall" /tmp/timing-before.log /tmp/timing-after.log
