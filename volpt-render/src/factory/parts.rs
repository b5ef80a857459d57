//! From a description's plain data to the parts of a scene: each registry part says, in its
//! axis's file, when it represents the description exactly and how it is built ([`Part`]), and
//! the factory asks the parts of an axis in registry order. A part is simpler than the
//! description names only where the two are exactly equal ([`Simplification`]).
//!
//! - [`medium`]: the media, and which [`GridReads`] the description's lookup and storage ask for;
//! - [`boundary`], [`phase`], [`environment`]: the other axes.

use super::*;

pub mod boundary;
pub mod environment;
pub mod medium;
pub mod phase;

pub use boundary::BoundaryInput;
pub use environment::SampledEnvironment;
pub use medium::{MediumInput, ReadsRule, TrackedMedium};

/// A registry part as the factory builds it from a scene description. The factory asks the parts
/// of an axis in registry order ([`volpt_core::variant`]) and takes the first that accepts, so an
/// axis lists its specialised parts before its general ones; a part needs no other edit of the
/// factory.
pub trait Part<'a>: Sized {
    /// What the factory reads from the description for this axis, once for all its parts.
    type Input;

    /// This part for `input`, if it represents it exactly; `fired` hears of each
    /// [`Simplification`] that made it simpler than the description names.
    fn specialised(input: &Self::Input, fired: &mut dyn FnMut(Simplification)) -> Option<Self>;

    /// This part for `input`, if it is the most general part of its axis that represents it
    /// exactly ([`Effects::General`]).
    fn general(input: &Self::Input) -> Option<Self>;
}

/// A rule that made the factory pick a simpler part than the description names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simplification {
    /// A density grid with one value everywhere, covering the medium's box, is a constant
    /// extinction: homogeneous with a constant albedo, a one-voxel density grid beside an albedo grid.
    ConstantDensityGrid,
    /// An albedo grid with one value everywhere, covering the medium's box, is a constant albedo.
    ConstantAlbedoGrid,
    /// Henyey-Greenstein with g = 0 is isotropic.
    ZeroAsymmetry,
    /// A smooth dielectric with relative IOR exactly 1 neither reflects nor bends: index-matched.
    /// Only where depth is not counted (unlimited max_depth, no roulette), because a dielectric
    /// crossing counts as an interaction and an index-matched one does not.
    UnitIorRatio,
}

impl fmt::Display for Simplification {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Simplification::ConstantDensityGrid => {
                "the density grid has one value over the whole box: constant extinction"
            }
            Simplification::ConstantAlbedoGrid => {
                "the albedo grid has one value over the whole box: constant albedo"
            }
            Simplification::ZeroAsymmetry => "Henyey-Greenstein with g = 0: isotropic phase",
            Simplification::UnitIorRatio => {
                "dielectric with IOR ratio 1, depth not limited: index-matched boundary"
            }
        })
    }
}

pub(super) fn aabb(b: &Bounds) -> Aabb {
    Aabb::new(Vec3::from_array(b.min), Vec3::from_array(b.max))
}
