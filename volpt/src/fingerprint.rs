//! What makes two renders the same render, as one 64-bit hash: the scene as loaded (camera, film,
//! integrator limits, boundary, medium with its grids and their storage, environment with its map),
//! the resolved path settings and the variant choice. Not the sample count (a render may continue
//! to more samples) and not the seed (checked on its own, with a clearer message).
//!
//! Every part is hashed through its serde serialisation (postcard's stable wire format, fed to
//! FNV-1a), so a field added to a description type is part of the fingerprint without anyone
//! remembering to add it; the scene's own fields are listed by an exhaustive pattern, so a new one
//! fails to compile until it is placed on one side or the other. The values of the grids and of
//! the environment map, which the description's serialisation leaves out, are hashed on their own
//! ([`content`]), once per scene: a scene's data does not change, its camera does at every frame
//! of a viewer.

use serde::Serialize;
use volpt_core::PathSettings;
use volpt_film::checkpoint::Fnv;
use volpt_render::Effects;
use volpt_scene::SceneDescription;

/// The fingerprint of rendering `desc` with `settings` and `effects`; `content` is [`content`]`(desc)`.
pub fn fingerprint(
    desc: &SceneDescription,
    settings: &PathSettings,
    effects: Effects,
    content: u64,
) -> u64 {
    let SceneDescription {
        camera,
        film,
        spp: _,
        integrator,
        boundary,
        medium,
        environment,
        lights,
    } = desc;
    let mut hasher = Hasher(Fnv::default());
    let identity = (
        camera,
        film,
        integrator,
        boundary,
        medium,
        environment,
        lights,
        settings,
        effects,
        content,
    );
    hasher.feed(&identity);
    hasher.0.finish()
}

/// The values of `desc`'s grids and environment map, each with its length, hashed (FNV-1a): what
/// the description's serialisation leaves out.
pub fn content(desc: &SceneDescription) -> u64 {
    let [density, albedo] = desc.medium.unserialised_values();
    let data = [density, albedo, desc.environment.unserialised_values()];
    let mut hash = Fnv::default();
    for values in data {
        hash.write(&(values.len() as u64).to_le_bytes());
        for v in values {
            hash.write(&v.to_le_bytes());
        }
    }
    hash.finish()
}

/// postcard's output, hashed as it is written instead of stored.
struct Hasher(Fnv);

impl Hasher {
    fn feed(&mut self, value: &impl Serialize) {
        // Serialising into a hash cannot fail: every description type is plain data.
        postcard::serialize_with_flavor(value, Flavor(&mut self.0))
            .expect("description types serialise");
    }
}

struct Flavor<'a>(&'a mut Fnv);

impl postcard::ser_flavors::Flavor for Flavor<'_> {
    type Output = ();

    fn try_push(&mut self, data: u8) -> postcard::Result<()> {
        self.0.write(&[data]);
        Ok(())
    }

    fn try_extend(&mut self, data: &[u8]) -> postcard::Result<()> {
        self.0.write(data);
        Ok(())
    }

    fn finalize(self) -> postcard::Result<()> {
        Ok(())
    }
}
