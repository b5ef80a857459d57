//! The rules that make a description select a simpler part than it names: each holds only where
//! the two are exactly equal.

use std::fmt;

/// A rule that made the factory pick a simpler part than the description names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simplification {
    /// A density grid with one value everywhere, covering the medium's box, is a constant
    /// extinction: homogeneous with a constant albedo, a one-voxel density grid beside an albedo grid.
    ConstantDensityGrid,
    /// An albedo grid with one value everywhere, covering the medium's box, is a constant albedo.
    ConstantAlbedoGrid,
    /// An RGB extinction whose channels are equal is grey: today's grey media, no spectral MIS.
    GreyExtinction,
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
            Simplification::GreyExtinction => {
                "the extinction is equal in R, G and B: grey medium, no spectral MIS"
            }
            Simplification::ZeroAsymmetry => "Henyey-Greenstein with g = 0: isotropic phase",
            Simplification::UnitIorRatio => {
                "dielectric with IOR ratio 1, depth not limited: index-matched boundary"
            }
        })
    }
}
