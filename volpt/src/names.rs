//! The words users type for the library's choices, one table per choice ([`Named`]): what the
//! command line's flags (`--lookup stochastic`) and Python's settings (`lookup="stochastic"`)
//! accept, list in their help and print, so that no front end keeps a table of its own.
//!
//! A name is refused by [`parse`] with [`Error::Setting`], keyed by the setting in the library's
//! spelling ([`Named::KEY`], `max_depth` style): each front end spells the key its own way
//! (`--max-depth`, `settings["max_depth"]`).

use volpt_core::{Estimator, Roulette};
use volpt_cuda::{Math, Strategy};
use volpt_film::Accumulation;
use volpt_gpu_mem::VolumeMemory;
use volpt_render::Effects;
use volpt_scene::GridLookup;

use crate::{BackendKind, Error, StrategyChoice, Tracking};

/// A choice a user names by a word.
pub trait Named: Copy + PartialEq + Send + Sync + std::fmt::Debug + 'static {
    /// The setting that takes these names, in the library's spelling (`lookup`).
    const KEY: &'static str;
    /// Every value, in the order help lists them.
    fn all() -> &'static [Self];
    /// The word users type.
    fn name(self) -> &'static str;
    /// What the value does, in one sentence for help texts.
    fn about(self) -> &'static str;
}

/// The value named `text`, or [`Error::Setting`] listing the names.
pub fn parse<T: Named>(text: &str) -> Result<T, Error> {
    T::all()
        .iter()
        .copied()
        .find(|v| v.name() == text)
        .ok_or_else(|| Error::Setting {
            key: T::KEY,
            expected: expected::<T>(),
            found: format!("{text:?}"),
        })
}

/// `one of a, b, c`: what a setting of `T` expects, as errors say it.
pub fn expected<T: Named>() -> String {
    format!("one of {}", names::<T>().join(", "))
}

/// Every name of `T`, in order.
pub fn names<T: Named>() -> Vec<&'static str> {
    T::all().iter().map(|v| v.name()).collect()
}

/// One table: the setting's key, then each value with its name and what it does.
macro_rules! named {
    ($ty:ty, $key:literal, [$(($value:expr, $name:literal, $about:literal)),+ $(,)?]) => {
        impl Named for $ty {
            const KEY: &'static str = $key;

            fn all() -> &'static [Self] {
                &[$($value),+]
            }

            fn name(self) -> &'static str {
                $(if self == $value {
                    return $name;
                })+
                unreachable!("every value is in the table")
            }

            fn about(self) -> &'static str {
                $(if self == $value {
                    return $about;
                })+
                unreachable!("every value is in the table")
            }
        }
    };
}

named!(
    BackendKind,
    "backend",
    [
        (BackendKind::Cpu, "cpu", "Every CPU core, through rayon."),
        (
            BackendKind::Cuda,
            "cuda",
            "An NVIDIA GPU through the CUDA driver."
        ),
    ]
);

named!(
    Tracking,
    "tracking",
    [
        (
            Tracking::Global,
            "global",
            "One majorant, the densest voxel's extinction, everywhere."
        ),
        (
            Tracking::Grid,
            "grid",
            "A majorant per cell of a coarse grid, walked by a 3D DDA."
        ),
    ]
);

named!(
    Estimator,
    "estimator",
    [
        (
            Estimator::PathTracing,
            "pt",
            "Path tracing: light only where a path escapes."
        ),
        (
            Estimator::NextEvent,
            "nee",
            "Next-event estimation of the environment at scattering events (index-matched \
         boundary) or at the boundary (rough dielectric), with MIS."
        ),
    ]
);

named!(GridLookup, "lookup", [
    (GridLookup::Trilinear, "trilinear", "Trilinear interpolation of the eight samples around a point."),
    (GridLookup::Nearest, "nearest", "The nearest sample's value: one read instead of eight."),
    (
        GridLookup::Texture,
        "texture",
        "Trilinear filtering by the GPU's texture unit (weights with 8 fractional bits; the CPU \
         computes the same filter): one instruction per lookup, an approximation of trilinear."
    ),
    (
        GridLookup::TextureHalf,
        "texture-f16",
        "texture, of samples held in half precision (rounded toward zero; at most 65504)."
    ),
    (
        GridLookup::Stochastic,
        "stochastic",
        "One of the eight samples, chosen with probability its trilinear weight: an unbiased \
         estimate of trilinear for one read (on the GPU one unfiltered texel)."
    ),
]);

named!(
    Roulette,
    "roulette",
    [
        (
            Roulette::Mitsuba,
            "mitsuba",
            "Mitsuba's: min(max(throughput) * eta^2, 0.95)."
        ),
        (
            Roulette::Throughput,
            "throughput",
            "The thesis's: min(1, max(throughput) * eta^2) (its throughput leaves out the \
         radiance's 1/eta^2 inside a denser medium)."
        ),
    ]
);

named!(
    Effects,
    "effects",
    [
        (
            Effects::Specialised,
            "specialised",
            "Simulate only the effects the scene calls for (the variant specialised to it)."
        ),
        (
            Effects::General,
            "general",
            "The most general variant (grid density and albedo, Henyey-Greenstein, lat-long map): \
         what specialisation saves."
        ),
    ]
);

named!(
    Accumulation,
    "accumulation",
    [
        (Accumulation::F64, "f64", "Every sample added in f64."),
        (
            Accumulation::F32,
            "f32",
            "Every sample added in f32, as an f32 film would (CPU backend only)."
        ),
    ]
);

named!(
    Math,
    "math",
    [
        (
            Math::Exact,
            "exact",
            "IEEE-rounded arithmetic and libm, bit-identical to the CPU (naive-sk)."
        ),
        (
            Math::Fast,
            "fast",
            "The GPU's approximate instructions: faster, statistically equal, not bit-identical."
        ),
    ]
);

named!(
    VolumeMemory,
    "volume_memory",
    [
        (
            VolumeMemory::Device,
            "device",
            "Copied to device memory (fastest; the volume must fit)."
        ),
        (
            VolumeMemory::ZeroCopy,
            "zerocopy",
            "Page-locked host memory mapped into the device's address space: every lookup crosses \
         PCIe, nothing is copied ahead."
        ),
        (
            VolumeMemory::Managed,
            "managed",
            "Managed memory: what fits the budget is prefetched to the device, the rest read \
         remotely."
        ),
        (
            VolumeMemory::Auto,
            "auto",
            "On the device while the volumes fit the budget, zero-copy beyond it."
        ),
    ]
);

impl Named for Strategy {
    const KEY: &'static str = "strategy";

    fn all() -> &'static [Self] {
        Strategy::ALL
    }

    fn name(self) -> &'static str {
        Strategy::name(self)
    }

    fn about(self) -> &'static str {
        "A GPU scheduling strategy (docs/strategies.md)."
    }
}

impl Named for StrategyChoice {
    const KEY: &'static str = "strategy";

    fn all() -> &'static [Self] {
        static ALL: std::sync::LazyLock<Vec<StrategyChoice>> = std::sync::LazyLock::new(|| {
            std::iter::once(StrategyChoice::Auto)
                .chain(Strategy::ALL.iter().map(|&s| StrategyChoice::Fixed(s)))
                .collect()
        });
        &ALL
    }

    fn name(self) -> &'static str {
        match self {
            StrategyChoice::Auto => "auto",
            StrategyChoice::Fixed(s) => s.name(),
        }
    }

    fn about(self) -> &'static str {
        match self {
            StrategyChoice::Auto => {
                "The fastest strategy for the scene on this GPU, by calibration renders, cached."
            }
            StrategyChoice::Fixed(s) => Named::about(s),
        }
    }
}

/// `Display` and `FromStr` by the table, for the choices this crate defines (those of the
/// crates below it have their own, or are named through [`Named`] and [`parse`]).
macro_rules! display_from_str {
    ($($ty:ty),*) => {$(
        impl std::fmt::Display for $ty {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(Named::name(*self))
            }
        }

        impl std::str::FromStr for $ty {
            type Err = Error;

            fn from_str(s: &str) -> Result<Self, Error> {
                parse(s)
            }
        }
    )*};
}

display_from_str!(BackendKind, Tracking);

impl std::str::FromStr for StrategyChoice {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self, Error> {
        parse(s)
    }
}
