//! What the factory builds every medium from: the description's medium with each grid of one
//! value over the box as that constant, found with the factory's [`FactoryCache`]. The media's
//! rules ([`FromDescription`] for each registry medium, and which [`volpt_core::grid::GridReads`]
//! the description's lookup and storage ask for, [`ReadsRule`]) are in `volpt-scene`'s medium file
//! ([`volpt_scene::medium`]), beside the phase's, the boundary's and the environment's.

use super::*;

pub use volpt_scene::medium::IsUniform;
pub use volpt_scene::{MediumInput, ReadsRule};

/// `desc`'s medium as the factory's medium parts read it: for [`Effects::Specialised`], a grid of
/// one value over the box as that constant (each such grid reported to `fired`).
pub fn medium_input<'a>(
    desc: &'a SceneDescription,
    effects: Effects,
    cache: &FactoryCache,
    fired: &mut dyn FnMut(Simplification),
) -> MediumInput<'a> {
    let is_uniform = |data: &[f32], channels: usize| cache.is_uniform(data, channels);
    let is_uniform: Option<&IsUniform<'_>> = match effects {
        Effects::Specialised => Some(&is_uniform),
        Effects::General => None,
    };
    MediumInput::of(desc, is_uniform, fired)
}

pub(super) fn aabb(b: &Bounds) -> Aabb {
    Aabb::new(Vec3::from_array(b.min), Vec3::from_array(b.max))
}
