//! The environments: a constant, or a latitude-longitude map (the general one: a constant is a
//! one-texel map).

use super::*;

/// What the factory derives from an environment for next-event estimation: a map's sampling
/// distribution ([`Derived`]); any other environment keeps the defaults.
pub trait SampledEnvironment<'a> {
    /// The distribution next-event estimation samples directions from, if the environment has one.
    fn distribution(&self) -> Option<Vec<f32>> {
        None
    }

    /// Samples from `distribution` (what [`SampledEnvironment::distribution`] gave).
    fn sample_from(&mut self, distribution: &'a [f32]) {
        let _ = distribution;
    }
}

impl<'a> Part<'a> for ConstantEnvironment {
    type Input = &'a EnvironmentDesc;

    fn specialised(input: &&'a EnvironmentDesc, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match input {
            EnvironmentDesc::Constant(rgb) => Some(ConstantEnvironment(Spectrum::from_array(*rgb))),
            EnvironmentDesc::LatLong(_) => None,
        }
    }

    fn general(_: &&'a EnvironmentDesc) -> Option<Self> {
        None
    }
}

impl SampledEnvironment<'_> for ConstantEnvironment {}

impl<'a> Part<'a> for LatLongEnvironment<'a> {
    type Input = &'a EnvironmentDesc;

    fn specialised(input: &&'a EnvironmentDesc, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match input {
            EnvironmentDesc::LatLong(map) => Some(lat_long(map)),
            EnvironmentDesc::Constant(_) => None,
        }
    }

    fn general(input: &&'a EnvironmentDesc) -> Option<Self> {
        Some(match input {
            EnvironmentDesc::Constant(rgb) => LatLongEnvironment::new(
                rgb,
                1,
                1,
                LatLongRows::CellCentred,
                [Vec3::X, Vec3::Y, Vec3::Z],
                1.0,
            ),
            EnvironmentDesc::LatLong(map) => lat_long(map),
        })
    }
}

impl<'a> SampledEnvironment<'a> for LatLongEnvironment<'a> {
    fn distribution(&self) -> Option<Vec<f32>> {
        let mut data = vec![0.0; LatLongEnvironment::distribution_len(self.width, self.height)];
        self.fill_distribution(&mut data);
        Some(data)
    }

    fn sample_from(&mut self, distribution: &'a [f32]) {
        self.distribution = distribution;
    }
}

/// The map's world-to-map rotation is the transpose of its `to_world`'s linear part (a rotation,
/// as the loader checks); the translation does not matter for light from infinitely far away.
fn lat_long(map: &LatLongDesc) -> LatLongEnvironment<'_> {
    let m = map.to_world;
    let column = |j: usize| Vec3::new(m[0][j], m[1][j], m[2][j]);
    let rows = match map.rows {
        volpt_scene::description::LatLongRows::CellCentred => LatLongRows::CellCentred,
        volpt_scene::description::LatLongRows::PoleToPole => LatLongRows::PoleToPole,
    };
    LatLongEnvironment::new(
        &map.rgb,
        map.width,
        map.height,
        rows,
        [column(0), column(1), column(2)],
        map.scale,
    )
}
