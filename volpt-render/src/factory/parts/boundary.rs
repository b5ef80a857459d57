//! The boundaries: the description's BSDF, index-matched where a dielectric of IOR ratio 1 is
//! exactly that.

use super::*;

/// What the factory reads for the boundary axis.
#[derive(Clone, Copy, Debug)]
pub struct BoundaryInput {
    pub bsdf: BsdfDesc,
    /// Neither depth limit nor roulette: the path does not count its interactions.
    pub depth_not_counted: bool,
}

impl BoundaryInput {
    pub fn of(desc: &SceneDescription) -> Self {
        Self {
            bsdf: desc.boundary.bsdf,
            depth_not_counted: desc.integrator.max_depth.is_none()
                && desc.integrator.rr_depth.is_none(),
        }
    }
}

impl Part<'_> for NullBoundary {
    type Input = BoundaryInput;

    fn specialised(input: &BoundaryInput, fired: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match input.bsdf {
            BsdfDesc::Null => Some(NullBoundary),
            BsdfDesc::Dielectric { int_ior, ext_ior }
                if int_ior == ext_ior && input.depth_not_counted =>
            {
                fired(Simplification::UnitIorRatio);
                Some(NullBoundary)
            }
            _ => None,
        }
    }

    /// No other boundary equals an index-matched one exactly; the rule that makes a unit IOR ratio
    /// index-matched holds here too, unreported.
    fn general(input: &BoundaryInput) -> Option<Self> {
        Self::specialised(input, &mut |_| ())
    }
}

impl Part<'_> for SmoothDielectric {
    type Input = BoundaryInput;

    fn specialised(input: &BoundaryInput, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match input.bsdf {
            BsdfDesc::Dielectric { int_ior, ext_ior } => Some(SmoothDielectric {
                eta: int_ior / ext_ior,
            }),
            _ => None,
        }
    }

    /// No rough dielectric equals a smooth one exactly.
    fn general(input: &BoundaryInput) -> Option<Self> {
        Self::specialised(input, &mut |_| ())
    }
}

impl Part<'_> for RoughDielectric {
    type Input = BoundaryInput;

    fn specialised(input: &BoundaryInput, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match input.bsdf {
            BsdfDesc::RoughDielectric {
                alpha,
                int_ior,
                ext_ior,
            } => Some(RoughDielectric {
                eta: int_ior / ext_ior,
                distribution: Ggx { alpha },
            }),
            _ => None,
        }
    }

    fn general(input: &BoundaryInput) -> Option<Self> {
        Self::specialised(input, &mut |_| ())
    }
}
