//! Kernels that test the strategies' collective building blocks against plain CPU code
//! (`volpt selftest --backend cuda`, `volpt_cuda::selftest`): the block-wide exclusive count of
//! streaming's compaction, the block-wide radix sort of the sorting strategies, the warp and block index takers of regeneration, and grid lookups
//! through textures (against the CPU's filter). Each thread reads its input, runs the building
//! block, and writes what it got.

/// The selftest kernels' entry points, as [`export_selftests!`](crate::export_selftests) exports
/// them.
pub const ENTRIES: [&str; 7] = [
    "selftest__block_exclusive_count",
    "selftest__block_sort",
    "selftest__warp_take_indices",
    "selftest__block_take_indices",
    "selftest__texture_lookups_1",
    "selftest__texture_lookups_3",
    "selftest__math_functions",
];

/// Exports the selftest kernels (the workspace's kernels crate invokes it once).
#[macro_export]
macro_rules! export_selftests {
    () => {
        const _: () = {
            /// # Safety
            /// As [`volpt_device::selftest::block_exclusive_count`].
            #[export_name = "selftest__block_exclusive_count"]
            pub unsafe extern "ptx-kernel" fn block_exclusive_count(
                preds: *const u32,
                out: *mut u32,
            ) {
                // SAFETY: forwarded.
                unsafe { $crate::selftest::block_exclusive_count(preds, out) }
            }
            /// # Safety
            /// As [`volpt_device::selftest::block_sort`].
            #[export_name = "selftest__block_sort"]
            pub unsafe extern "ptx-kernel" fn block_sort(keys: *const u32, out: *mut u32) {
                // SAFETY: forwarded.
                unsafe { $crate::selftest::block_sort(keys, out) }
            }
            /// # Safety
            /// As [`volpt_device::selftest::warp_take_indices`].
            #[export_name = "selftest__warp_take_indices"]
            pub unsafe extern "ptx-kernel" fn warp_take_indices(
                needs: *const u32,
                next: *mut u64,
                out: *mut u64,
            ) {
                // SAFETY: forwarded.
                unsafe { $crate::selftest::take_indices(needs, next, out, false) }
            }
            /// # Safety
            /// As [`volpt_device::selftest::warp_take_indices`].
            #[export_name = "selftest__block_take_indices"]
            pub unsafe extern "ptx-kernel" fn block_take_indices(
                needs: *const u32,
                next: *mut u64,
                out: *mut u64,
            ) {
                // SAFETY: forwarded.
                unsafe { $crate::selftest::take_indices(needs, next, out, true) }
            }
            /// # Safety
            /// As [`volpt_device::selftest::texture_lookups`].
            #[export_name = "selftest__texture_lookups_1"]
            pub unsafe extern "ptx-kernel" fn texture_lookups_1(
                grid: *const volpt_core::abi::GridParams,
                points: *const f32,
                out: *mut f32,
                n: u32,
            ) {
                // SAFETY: forwarded.
                unsafe { $crate::selftest::texture_lookups::<1>(grid, points, out, n) }
            }
            /// # Safety
            /// As [`volpt_device::selftest::texture_lookups`].
            #[export_name = "selftest__texture_lookups_3"]
            pub unsafe extern "ptx-kernel" fn texture_lookups_3(
                grid: *const volpt_core::abi::GridParams,
                points: *const f32,
                out: *mut f32,
                n: u32,
            ) {
                // SAFETY: forwarded.
                unsafe { $crate::selftest::texture_lookups::<3>(grid, points, out, n) }
            }
            /// # Safety
            /// As [`volpt_device::selftest::math_functions`].
            #[export_name = "selftest__math_functions"]
            pub unsafe extern "ptx-kernel" fn math_functions(
                inputs: *const f32,
                out: *mut f32,
                fast: *mut u32,
                n: u32,
            ) {
                // SAFETY: forwarded.
                unsafe { $crate::selftest::math_functions(inputs, out, fast, n) }
            }
        };
    };
}

/// Thread `i` writes `block_exclusive_count(preds[i] != 0)` as `out[2i], out[2i + 1]`.
///
/// # Safety
/// `preds` and `out` must hold one and two `u32` per thread of the launch, whose blocks are
/// `BLOCK_SIZE` threads.
#[cfg(target_arch = "nvptx64")]
#[inline(always)]
pub unsafe fn block_exclusive_count(preds: *const u32, out: *mut u32) {
    use crate::nvptx::{block_exclusive_count, global_thread_index, opaque};
    let i = global_thread_index() as usize;
    // SAFETY: the caller's contract.
    let pred = unsafe { *preds.add(i) } != 0;
    let (rank, total) = block_exclusive_count(opaque(pred));
    // SAFETY: the caller's contract.
    unsafe {
        *out.add(2 * i) = rank;
        *out.add(2 * i + 1) = total;
    }
}

/// Thread `i` writes the key of its place in its block's sort of `keys` and the thread that held
/// it (`nvptx::block_sort_u32`) as `out[2i], out[2i + 1]`.
///
/// # Safety
/// `keys` and `out` must hold one and two `u32` per thread of the launch, whose blocks are
/// `BLOCK_SIZE` threads.
#[cfg(target_arch = "nvptx64")]
#[inline(always)]
pub unsafe fn block_sort(keys: *const u32, out: *mut u32) {
    use crate::nvptx::{block_sort_u32, global_thread_index, opaque_u32};
    let i = global_thread_index() as usize;
    // SAFETY: the caller's contract.
    let key = opaque_u32(unsafe { *keys.add(i) });
    let (sorted, source) = block_sort_u32(key);
    // SAFETY: the caller's contract.
    unsafe {
        *out.add(2 * i) = sorted;
        *out.add(2 * i + 1) = source;
    }
}

/// Thread `i` with `needs[i] != 0` takes an index from `*next` (with the warp's index taker, or
/// the block's if `block`) and writes it to `out[i]`; the others write `u64::MAX`.
///
/// # Safety
/// `needs` and `out` must hold one value per thread of the launch, whose blocks are `BLOCK_SIZE`
/// threads, and `next` one `u64`.
#[cfg(target_arch = "nvptx64")]
#[inline(always)]
pub unsafe fn take_indices(needs: *const u32, next: *mut u64, out: *mut u64, block: bool) {
    use crate::nvptx::{global_thread_index, opaque};
    use crate::strategy::{block_take_indices, warp_take_indices};
    let i = global_thread_index() as usize;
    // SAFETY: the caller's contract.
    let need = opaque(unsafe { *needs.add(i) } != 0);
    // SAFETY: the caller's contract.
    let taken = unsafe {
        if block {
            block_take_indices(need, next)
        } else {
            warp_take_indices(need, next)
        }
    };
    let index = match taken {
        Some(index) if need => index,
        _ => u64::MAX,
    };
    // SAFETY: the caller's contract.
    unsafe { *out.add(i) = index };
}

/// Thread `i < n` looks up the `C`-channel grid `grid` (in a texture) at point `i` (`points[3i..]`)
/// with [`volpt_core::TextureTrilinear`] and writes the `C` values to `out[C i..]`.
///
/// # Safety
/// `grid` must hold the parameters of a grid in a texture that lives for the launch, `points`
/// `3 n` values and `out` `C n`.
#[cfg(target_arch = "nvptx64")]
#[inline(always)]
pub unsafe fn texture_lookups<const C: usize>(
    grid: *const volpt_core::abi::GridParams,
    points: *const f32,
    out: *mut f32,
    n: u32,
) {
    use volpt_core::{GridReads, TextureTrilinear, Vec3};

    use crate::nvptx::global_thread_index;
    let i = global_thread_index() as usize;
    if i >= n as usize {
        return;
    }
    // SAFETY: the caller's contract.
    let (grid, p) = unsafe {
        let grid = (*grid).grid::<C>();
        let p = Vec3::new(
            *points.add(3 * i),
            *points.add(3 * i + 1),
            *points.add(3 * i + 2),
        );
        (grid, p)
    };
    let v = TextureTrilinear::lookup(&grid, p);
    for (c, v) in v.into_iter().enumerate() {
        // SAFETY: the caller's contract.
        unsafe { *out.add(C * i + c) = v };
    }
}

/// Inputs per thread of [`math_functions`]: `(a, b, u)`.
pub const MATH_INPUTS: usize = 3;
/// Outputs per thread of [`math_functions`].
pub const MATH_OUTPUTS: usize = 7;

/// What [`math_functions`] computes for `(a, b, u)`: `sqrt(a)`, `ln(a)`, `exp(b)`, `a / b`
/// (`math::div`), `1 / b` (`math::recip`) and `sin_cos_2pi(u)`, through `volpt_core::math` as
/// the build that calls it compiles it: in a kernel, the kernels' arithmetic; on the host, the
/// CPU's, which the exact kernels must match bit for bit.
#[inline(always)]
pub fn math_values(a: f32, b: f32, u: f32) -> [f32; MATH_OUTPUTS] {
    use volpt_core::{math, Vec3};
    let (sin, cos) = math::sin_cos_2pi(u);
    [
        math::sqrt(a),
        math::ln(a),
        math::exp(b),
        math::div(Vec3::splat(a), Vec3::splat(b)).x,
        math::recip(Vec3::splat(b)).x,
        sin,
        cos,
    ]
}

/// Thread `i < n` reads `(a, b, u) = inputs[3i..]` and writes [`math_values`] to `out[7i..]`;
/// thread 0 writes to `*fast` whether this is the fast-math build.
///
/// # Safety
/// `inputs` must hold `3 n` values, `out` `7 n` and `fast` one.
#[cfg(target_arch = "nvptx64")]
#[inline(always)]
pub unsafe fn math_functions(inputs: *const f32, out: *mut f32, fast: *mut u32, n: u32) {
    use crate::nvptx::global_thread_index;
    let i = global_thread_index() as usize;
    if i == 0 {
        // SAFETY: the caller's contract.
        unsafe { *fast = u32::from(volpt_core::math::FAST) };
    }
    if i >= n as usize {
        return;
    }
    // SAFETY: the caller's contract.
    let (a, b, u) = unsafe {
        let p = inputs.add(MATH_INPUTS * i);
        (*p, *p.add(1), *p.add(2))
    };
    for (k, v) in math_values(a, b, u).into_iter().enumerate() {
        // SAFETY: the caller's contract.
        unsafe { *out.add(MATH_OUTPUTS * i + k) = v };
    }
}
