//! Which arithmetic the kernels use: a build of the same source, chosen at run time.

/// `exact` kernels compute the CPU's bits; `fast` kernels use the GPU's approximate instructions
/// (`lg2`/`ex2`/`sqrt.approx`, approximate division, fused multiply-adds), built from the same source
/// with `--cfg volpt_fast_math` (`cargo xtask ptx`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Math {
    /// IEEE-rounded arithmetic and libm, bit-identical to the CPU (naive-sk).
    #[default]
    Exact,
    /// The GPU's approximate instructions: faster, statistically equal, not bit-identical.
    Fast,
}

impl Math {
    pub const ALL: &'static [Math] = &[Math::Exact, Math::Fast];

    /// The name users type: `--math fast`.
    pub fn name(self) -> &'static str {
        match self {
            Math::Exact => "exact",
            Math::Fast => "fast",
        }
    }
}

impl core::fmt::Display for Math {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}
