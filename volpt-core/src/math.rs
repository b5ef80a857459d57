//! Scalar math used by the estimators, in one place so that every backend computes the same bits.
//!
//! `core` has no `sqrt`/`ln`/`sin` on stable; `libm` is pure Rust and compiles for every target,
//! including nvptx64. A GPU backend may later swap in hardware approximations behind the same names
//! (an accuracy/time knob that must be measured, see DESIGN.md section 2).

pub const PI: f32 = core::f32::consts::PI;
pub const INV_PI: f32 = core::f32::consts::FRAC_1_PI;
pub const INV_4PI: f32 = 0.25 * core::f32::consts::FRAC_1_PI;

/// The correctly rounded square root (IEEE 754), so every backend gets the same bits.
#[inline]
pub fn sqrt(x: f32) -> f32 {
    #[cfg(target_arch = "nvptx64")]
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

/// `sqrt(max(x, 0))`: rounding can push a quantity that is non-negative in exact arithmetic below 0.
#[inline]
pub fn safe_sqrt(x: f32) -> f32 {
    sqrt(x.max(0.0))
}

#[inline]
pub fn ln(x: f32) -> f32 {
    libm::logf(x)
}

#[inline]
pub fn exp(x: f32) -> f32 {
    libm::expf(x)
}

#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    libm::sincosf(x)
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
