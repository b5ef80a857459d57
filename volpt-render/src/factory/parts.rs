//! From a medium's description to the medium part of a scene: each registry medium says when it
//! represents the description exactly and how it is built ([`Part`]), and the factory asks them in
//! registry order. A part is simpler than the description names only where the two are exactly
//! equal ([`Simplification`]).
//!
//! - [`medium`]: the media, and which [`GridReads`] the description's lookup and storage ask for.
//!
//! The phase, boundary and environment parts have their rules beside their descriptions, in
//! `volpt-scene`'s axis files ([`volpt_scene::FromDescription`]): their parts need nothing the
//! factory derives. A medium's rule stays here because the factory derives its grids' reads
//! ([`ReadsRule`]) and its majorant grid ([`TrackedMedium`]) from the built part.

use super::*;

pub mod medium;

pub use medium::{MediumInput, ReadsRule, TrackedMedium};

/// A registry medium as the factory builds it from a scene description
/// ([`volpt_scene::FromDescription`]'s shape, which a trait of `volpt-scene` cannot have for the
/// media's rules here). The factory asks the media in registry order ([`volpt_core::variant`]) and
/// takes the first that accepts, so the axis lists its specialised parts before its general ones;
/// a part needs no other edit of the factory.
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

pub(super) fn aabb(b: &Bounds) -> Aabb {
    Aabb::new(Vec3::from_array(b.min), Vec3::from_array(b.max))
}
