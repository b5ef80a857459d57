#!/bin/bash
# Both flavours as `cargo xtask ptx` runs them, the exact one with -Ztime-passes on the kernels crate.
cd /work/wt-pool
common=(rustc -Zbuild-std=core --target nvptx64-nvidia-cuda --profile nvptx -p volpt-kernels --lib)
export RUSTC_BOOTSTRAP=1 CARGO_TARGET_NVPTX64_NVIDIA_CUDA_LINKER=/bin/true
uptime
start=$(date +%s)
( CARGO_TARGET_NVPTX64_NVIDIA_CUDA_RUSTFLAGS="-C target-cpu=sm_70 --cfg volpt_fast_math -C llvm-args=-nvptx-prec-divf32=0 -C llvm-args=-nvptx-prec-sqrtf32=0 -C llvm-args=-nvptx-fma-level=2" \
  /usr/bin/time -f "fast: %e s wall %U s user" cargo "${common[@]}" --target-dir target-ptx/fast -- --emit=asm ) &
CARGO_TARGET_NVPTX64_NVIDIA_CUDA_RUSTFLAGS="-C target-cpu=sm_70" /usr/bin/time -f "exact: %e s wall %U s user" cargo "${common[@]}" --target-dir target-ptx -- --emit=asm -Ztime-passes
wait
echo "both: $(( $(date +%s) - start )) s"
uptime
