//! The phase functions: isotropic where Henyey-Greenstein's asymmetry is 0, Henyey-Greenstein
//! as the general one.

use super::*;

impl Part<'_> for Isotropic {
    type Input = PhaseDesc;

    fn specialised(input: &PhaseDesc, fired: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match *input {
            PhaseDesc::Isotropic => Some(Isotropic),
            PhaseDesc::HenyeyGreenstein { g: 0.0 } => {
                fired(Simplification::ZeroAsymmetry);
                Some(Isotropic)
            }
            PhaseDesc::HenyeyGreenstein { .. } => None,
        }
    }

    fn general(_: &PhaseDesc) -> Option<Self> {
        None
    }
}

impl Part<'_> for HenyeyGreenstein {
    type Input = PhaseDesc;

    fn specialised(input: &PhaseDesc, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match *input {
            PhaseDesc::HenyeyGreenstein { g } => Some(HenyeyGreenstein { g }),
            PhaseDesc::Isotropic => None,
        }
    }

    /// Isotropic scattering is Henyey-Greenstein with g = 0.
    fn general(input: &PhaseDesc) -> Option<Self> {
        Some(match *input {
            PhaseDesc::Isotropic => HenyeyGreenstein { g: 0.0 },
            PhaseDesc::HenyeyGreenstein { g } => HenyeyGreenstein { g },
        })
    }
}
