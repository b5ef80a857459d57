//! How a registry part of each axis is built from its description: each axis's file
//! ([`crate::medium`], [`crate::phase`], [`crate::boundary`], [`crate::environment`]) implements
//! [`FromDescription`] for that axis's parts (`volpt_core::variant`), and the render factory asks
//! an axis's parts in registry order, taking the first that accepts. What the factory derives from
//! a built part (a medium's majorant grid, an environment's sampling distribution) is the part's
//! own, beside its type in `volpt-core` (`TrackedMedium`, `SampledEnvironment`).

use crate::simplification::Simplification;

/// A registry part as the factory builds it from a scene description. An axis lists its
/// specialised parts before its general ones, so a part's rule needs no other edit of the factory.
pub trait FromDescription<'a>: Sized {
    /// What the factory reads from the description for this axis, once for all its parts.
    type Input;

    /// This part for `input`, if it represents it exactly; `fired` hears of each
    /// [`Simplification`] that made it simpler than the description names.
    fn specialised(input: &Self::Input, fired: &mut dyn FnMut(Simplification)) -> Option<Self>;

    /// This part for `input`, if it is the most general part of its axis that represents it
    /// exactly (the factory's `Effects::General`).
    fn general(input: &Self::Input) -> Option<Self>;
}
