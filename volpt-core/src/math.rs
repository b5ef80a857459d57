//! Scalar math used by the estimators, in one place so that every backend computes the same bits.
//!
//! `core` has no `sqrt`/`ln`/`sin` on stable; `libm` is pure Rust and compiles for every target,
//! including nvptx64, and gives every backend the same bits.
//!
//! The GPU's fast-math kernels (`--math fast`: built with `--cfg volpt_fast_math`, see
//! `cargo xtask ptx`) swap in the hardware approximations behind the same names: `lg2.approx`,
//! `ex2.approx`, `sqrt.approx`, `rcp.approx` and `div.approx` (relative errors of a few ulp, PTX
//! ISA 9.7.3), an accuracy/time knob measured in `docs/strategies.md`; they are no longer
//! bit-identical to the CPU. They flush subnormals to zero (`.ftz`): without it ptxas scales
//! every input into the normal range and back (three instructions around each, on the chain of
//! dependent instructions that sets the pace of a launch's last, longest paths), for arguments
//! that a renderer's sampled quantities do not reach or that round to nothing it would see.

/// Whether this build computes with the GPU's approximate instructions (the fast kernels).
pub const FAST: bool = cfg!(all(target_arch = "nvptx64", volpt_fast_math));

pub const PI: f32 = core::f32::consts::PI;
pub const INV_PI: f32 = core::f32::consts::FRAC_1_PI;
pub const INV_4PI: f32 = 0.25 * core::f32::consts::FRAC_1_PI;

/// The correctly rounded square root (IEEE 754), so every backend gets the same bits.
#[inline]
pub fn sqrt(x: f32) -> f32 {
    #[cfg(all(target_arch = "nvptx64", volpt_fast_math))]
    {
        approx::sqrt(x)
    }
    #[cfg(all(target_arch = "nvptx64", not(volpt_fast_math)))]
    {
        // `sqrt.rn` is IEEE round-to-nearest, the value libm's software square root computes, in one
        // instruction instead of an integer loop.
        let r: f32;
        // SAFETY: a pure arithmetic instruction on registers.
        unsafe {
            core::arch::asm!("sqrt.rn.f32 {r}, {x};", r = out(reg32) r, x = in(reg32) x,
                options(pure, nomem, nostack));
        }
        r
    }
    #[cfg(not(target_arch = "nvptx64"))]
    {
        libm::sqrtf(x)
    }
}

/// `v / |v|`, computed as glam's `Vec3::normalize` computes it (`v * (1 / sqrt(v . v))`, the dot
/// product summed x, y, z) but with this module's [`sqrt`]: glam's is libm's software square root,
/// which a GPU ran as ~40 instructions with a table read and 64-bit multiplies (four times per
/// rough-dielectric interaction, once per camera ray) where `sqrt.rn` is one. Correctly rounded
/// either way, so every backend's bits stay those of `normalize`.
#[inline(always)]
pub fn normalize(v: crate::Vec3) -> crate::Vec3 {
    v * (1.0 / sqrt(v.dot(v)))
}

/// `floor(x)` for `x` in `[0, 2^24)` (a grid's index coordinate, clamped): truncation, exact
/// there, one conversion each way where libm's `floorf` is a software routine on a GPU.
#[inline(always)]
pub fn floor_non_negative(x: f32) -> f32 {
    (x as u32) as f32
}

/// `v`, which the compiler cannot see through (on a GPU a pure assembly statement holding only
/// a comment; it may still move or drop it): [`crate::rng::unit_f32`] keeps its conversion from
/// 32 bits with it. Elsewhere `v` itself.
#[inline(always)]
pub fn opaque_u32(v: u32) -> u32 {
    #[cfg(target_arch = "nvptx64")]
    {
        let mut v = v;
        // SAFETY: a comment (no instruction) naming a register.
        unsafe { core::arch::asm!("// {v}", v = inout(reg32) v, options(pure, nomem, nostack)) };
        v
    }
    #[cfg(not(target_arch = "nvptx64"))]
    {
        v
    }
}

/// `sqrt(max(x, 0))`: rounding can push a quantity that is non-negative in exact arithmetic below 0.
#[inline]
pub fn safe_sqrt(x: f32) -> f32 {
    sqrt(x.max(0.0))
}

#[inline]
pub fn ln(x: f32) -> f32 {
    #[cfg(all(target_arch = "nvptx64", volpt_fast_math))]
    {
        approx::lg2(x) * core::f32::consts::LN_2
    }
    #[cfg(not(all(target_arch = "nvptx64", volpt_fast_math)))]
    {
        libm::logf(x)
    }
}

#[inline]
pub fn exp(x: f32) -> f32 {
    #[cfg(all(target_arch = "nvptx64", volpt_fast_math))]
    {
        approx::ex2(x * core::f32::consts::LOG2_E)
    }
    #[cfg(not(all(target_arch = "nvptx64", volpt_fast_math)))]
    {
        libm::expf(x)
    }
}

/// `a / b` per component: the correctly rounded quotient, or in the fast kernels `div.approx`.
#[inline]
pub fn div(a: crate::Vec3, b: crate::Vec3) -> crate::Vec3 {
    #[cfg(all(target_arch = "nvptx64", volpt_fast_math))]
    {
        crate::Vec3::new(
            approx::div(a.x, b.x),
            approx::div(a.y, b.y),
            approx::div(a.z, b.z),
        )
    }
    #[cfg(not(all(target_arch = "nvptx64", volpt_fast_math)))]
    {
        a / b
    }
}

/// `1 / v` per component: the correctly rounded reciprocal, or in the fast kernels `rcp.approx`.
#[inline]
pub fn recip(v: crate::Vec3) -> crate::Vec3 {
    #[cfg(all(target_arch = "nvptx64", volpt_fast_math))]
    {
        crate::Vec3::new(approx::rcp(v.x), approx::rcp(v.y), approx::rcp(v.z))
    }
    #[cfg(not(all(target_arch = "nvptx64", volpt_fast_math)))]
    {
        v.recip()
    }
}

/// `a / b`: the correctly rounded quotient, or in the fast kernels `div.approx` ([`div`]'s
/// arithmetic for one component, so that a mesh's planes and the box's slabs agree bit for bit).
#[inline]
pub fn div_scalar(a: f32, b: f32) -> f32 {
    div(crate::Vec3::splat(a), crate::Vec3::splat(b)).x
}

/// `1 / x`: [`recip`]'s arithmetic for one component.
#[inline]
pub fn recip_scalar(x: f32) -> f32 {
    recip(crate::Vec3::splat(x)).x
}

/// The GPU's approximate instructions, one function each.
#[cfg(all(target_arch = "nvptx64", volpt_fast_math))]
mod approx {
    macro_rules! unary {
        ($($name:ident: $op:literal),*) => {$(
            #[inline(always)]
            pub fn $name(x: f32) -> f32 {
                let r: f32;
                // SAFETY: a pure arithmetic instruction on registers.
                unsafe {
                    core::arch::asm!(concat!($op, " {r}, {x};"), r = out(reg32) r, x = in(reg32) x,
                        options(pure, nomem, nostack))
                };
                r
            }
        )*};
    }
    unary!(
        sqrt: "sqrt.approx.ftz.f32",
        lg2: "lg2.approx.ftz.f32",
        ex2: "ex2.approx.ftz.f32",
        rcp: "rcp.approx.ftz.f32"
    );

    #[inline(always)]
    pub fn div(a: f32, b: f32) -> f32 {
        let r: f32;
        // SAFETY: a pure arithmetic instruction on registers.
        unsafe {
            core::arch::asm!("div.approx.ftz.f32 {r}, {a}, {b};", r = out(reg32) r, a = in(reg32) a,
                b = in(reg32) b, options(pure, nomem, nostack))
        };
        r
    }
}

#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    libm::sincosf(x)
}

/// `(sin 2 pi u, cos 2 pi u)`: the azimuth of every direction sampler.
///
/// `u` is a fraction of a turn, so the reduction to a quarter turn is exact (`4u` and its nearest
/// integer are exact in f32), and no Payne-Hanek reduction is needed, unlike `sincosf(2 pi u)`;
/// on a GPU that path alone costs a 584-byte stack frame in local memory. What is left,
/// `theta = pi/2 r` with `|r| <= 1/2`, is a Taylor polynomial whose first omitted term is below
/// 2e-9. The quadrant then permutes and negates the pair.
#[inline]
pub fn sin_cos_2pi(u: f32) -> (f32, f32) {
    const S: [f32; 5] = [
        1.5707964,
        -0.6459641,
        0.079692625,
        -0.004681754,
        0.00016044118,
    ];
    const C: [f32; 6] = [
        1.0,
        -1.2337005,
        0.2536695,
        -0.02086348,
        0.00091926026,
        -2.5202042e-05,
    ];
    // Samplers pass u in [0, 1); anything else is first wrapped into it.
    let u = if (0.0..1.0).contains(&u) {
        u
    } else {
        u - libm::floorf(u)
    };
    let q = 4.0 * u;
    // Nearest quadrant by truncation (q + 0.5 is exact or rounds within its integer interval):
    // one conversion instruction, where libm's roundf is a software routine on baseline x86-64.
    let k = (q + 0.5) as u32;
    let r = q - k as f32;
    let r2 = r * r;
    let sin = r * (S[0] + r2 * (S[1] + r2 * (S[2] + r2 * (S[3] + r2 * S[4]))));
    let cos = C[0] + r2 * (C[1] + r2 * (C[2] + r2 * (C[3] + r2 * (C[4] + r2 * C[5]))));
    // Quadrant k maps (sin, cos) to (sin, cos), (cos, -sin), (-sin, -cos), (-cos, sin): a swap on
    // bit 0 and sign flips (exactly negation) on bit 1 of k and of k + 1, written as selects and
    // sign-bit masks. A `match` on the quadrant became a four-way indirect branch on the GPU, which
    // the lanes of a warp take apart: the top stall of the index-matched cube (ncu, H100,
    // 2026-11-25, docs/strategies.md).
    let (a, b) = if k & 1 == 0 { (sin, cos) } else { (cos, sin) };
    let sign = |bit: u32| (bit & 2) << 30;
    (
        f32::from_bits(a.to_bits() ^ sign(k)),
        f32::from_bits(b.to_bits() ^ sign(k.wrapping_add(1))),
    )
}

#[inline]
pub fn tan(x: f32) -> f32 {
    libm::tanf(x)
}

#[inline]
pub fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
    x.max(lo).min(hi)
}

#[inline]
pub fn sqr(x: f32) -> f32 {
    x * x
}

#[inline]
pub fn lerp(t: f32, a: f32, b: f32) -> f32 {
    (1.0 - t) * a + t * b
}
