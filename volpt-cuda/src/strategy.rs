//! The GPU scheduling strategies (Novák, Havran & Dachsbacher 2010; the thesis's naiveSK and
//! regenerationSK). The kernels themselves are in `volpt-cuda/kernels/src/strategy.rs`; this module
//! names them and decides how each is launched.

use std::fmt;
use std::str::FromStr;

use crate::error::CudaError;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Strategy {
    /// naiveSK: one thread per pixel traces one path per launch; the kernel is launched once per
    /// sample. A warp waits for its longest path.
    NaiveSk,
    /// regenerationSK: persistent threads, as many as the GPU holds at once, take path indices
    /// from a global atomic counter whenever their path ends.
    RegenerationSk,
}

/// Threads per block. A multiple of the warp size, as the warp-collective code requires.
pub(crate) const BLOCK_SIZE: u32 = 128;

/// Paths one regenerationSK launch aims at: enough to hide the tail of the last paths, few enough
/// that progress is reported a few times a second.
const PATHS_PER_REGENERATION_LAUNCH: u64 = 1 << 22;

impl Strategy {
    pub const ALL: [Strategy; 2] = [Strategy::NaiveSk, Strategy::RegenerationSk];

    /// The name users type: `--strategy naive-sk`.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::NaiveSk => "naive-sk",
            Strategy::RegenerationSk => "regeneration-sk",
        }
    }

    /// The kernel's entry point for a scene variant, as the kernels crate exports it:
    /// `<strategy>__<medium>__<boundary>__<phase>`, from the render factory's `medium/boundary/phase`.
    pub fn kernel_name(self, variant: &str) -> String {
        let strategy = self.name().replace('-', "_");
        let variant = variant.replace('/', "__").replace('-', "_");
        format!("{strategy}__{variant}")
    }

    /// Samples per pixel that one launch traces, out of `remaining`.
    pub(crate) fn samples_per_launch(self, pixels: u64, remaining: u32) -> u32 {
        match self {
            Strategy::NaiveSk => 1,
            Strategy::RegenerationSk => {
                let fit = (PATHS_PER_REGENERATION_LAUNCH / pixels.max(1)).max(1);
                remaining.min(u32::try_from(fit).unwrap_or(u32::MAX))
            }
        }
    }
}

impl fmt::Display for Strategy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Strategy {
    type Err = CudaError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Strategy::ALL
            .into_iter()
            .find(|strategy| strategy.name() == s)
            .ok_or_else(|| CudaError::UnknownStrategy {
                given: s.to_owned(),
                known: Strategy::ALL.map(Strategy::name).join(", "),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernel_names_follow_the_kernels_crate() {
        assert_eq!(
            Strategy::RegenerationSk.kernel_name("grid-density-albedo/rough-dielectric/hg"),
            "regeneration_sk__grid_density_albedo__rough_dielectric__hg"
        );
    }

    #[test]
    fn names_round_trip_and_unknown_names_are_errors() {
        for s in Strategy::ALL {
            assert_eq!(s.name().parse::<Strategy>().unwrap(), s);
        }
        let err = "warp-sk".parse::<Strategy>().unwrap_err().to_string();
        assert!(err.contains("warp-sk") && err.contains("naive-sk"), "{err}");
    }

    #[test]
    fn regeneration_launches_cover_all_samples() {
        assert_eq!(
            Strategy::RegenerationSk.samples_per_launch(160_000, 100),
            26
        );
        assert_eq!(Strategy::RegenerationSk.samples_per_launch(1 << 30, 100), 1);
        assert_eq!(Strategy::RegenerationSk.samples_per_launch(1, 7), 7);
        assert_eq!(Strategy::NaiveSk.samples_per_launch(1, 7), 1);
    }
}
