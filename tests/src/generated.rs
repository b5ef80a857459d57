//! Generated media that need nothing beside the checkout, for the estimator-against-estimator
//! tests that must run in CI: a heterogeneous density with holes (empty blocks, where tracking's
//! majorant grid has cells of bound 0 and ratio tracking's product is 1), an RGB albedo well below
//! 1 that varies over the box, under a constant or a lat-long environment. They stand in for smoke
//! and bucky (`../shared/data`), which CI lacks.
//!
//! The values come from volpt's own [`Rng`] with fixed seeds, so every run builds the same scenes.

use volpt_core::Rng;
use volpt_scene::description::*;
use volpt_scene::generate::Sky;

/// The unit cube [-0.5, 0.5]^3, the box of every generated medium.
pub const UNIT: Bounds = Bounds {
    min: [-0.5; 3],
    max: [0.5; 3],
};

/// A 12x10x8 cell-centred density over [`UNIT`]: a smooth lobe (0.2 to 1) times random voxel
/// factors (0.5 to 1), with about a quarter of its 2x2x2 blocks and a ball at the centre empty.
/// Its maximum is about 1; `scale` sets the extinction.
pub fn density_with_holes(seed: u32) -> GridDesc {
    let res = [12u32, 10, 8];
    let mut rng = Rng::new(seed, 0, 0);
    // Which 2x2x2 blocks are holes, drawn first so that the voxel values do not depend on them.
    let blocks: Vec<bool> = (0..6 * 5 * 4).map(|_| rng.next_f32() < 0.25).collect();
    let mut data = Vec::new();
    for z in 0..res[2] {
        for y in 0..res[1] {
            for x in 0..res[0] {
                let c = [x, y, z].map(|i| i as f32);
                let p = [0, 1, 2].map(|a| (c[a] + 0.5) / res[a] as f32 - 0.5);
                let hole = blocks[((z / 2) * 5 + y / 2) as usize * 6 + (x / 2) as usize]
                    || p.iter().map(|v| v * v).sum::<f32>() < 0.03;
                let lobe = 0.2 + 0.8 * (0.5 + 0.5 * (6.0 * p[0] + 4.0 * p[1] * p[2]).sin());
                let factor = 0.5 + 0.5 * rng.next_f32();
                data.push(if hole { 0.0 } else { lobe * factor });
            }
        }
    }
    GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution: res,
        channels: 1,
        bounds: UNIT,
        convention: GridConvention::Cell,
        data,
    }
}

/// A 5x4x6 RGB albedo grid over [`UNIT`], each channel of each sample random in `[lo, hi]`.
pub fn varying_albedo(seed: u32, (lo, hi): (f32, f32)) -> GridDesc {
    let res = [5u32, 4, 6];
    let mut rng = Rng::new(seed, 1, 0);
    let n = (res[0] * res[1] * res[2] * 3) as usize;
    GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution: res,
        channels: 3,
        bounds: UNIT,
        convention: GridConvention::Vertex,
        data: (0..n).map(|_| lo + (hi - lo) * rng.next_f32()).collect(),
    }
}

/// Albedo well below 1: a path's throughput falls at every collision, by a different factor per
/// channel.
pub const LOW_ALBEDO: (f32, f32) = (0.3, 0.8);

/// The generated heterogeneous medium: [`density_with_holes`] at `scale` (an optical depth of a
/// few through the box), [`varying_albedo`] in `albedo`, Henyey-Greenstein with `g`.
pub fn heterogeneous_medium(scale: f32, albedo: (f32, f32), g: f32) -> MediumDesc {
    MediumDesc {
        density: DensityDesc::Grid(density_with_holes(11)),
        scale,
        albedo: AlbedoDesc::Grid(varying_albedo(12, albedo)),
        phase: PhaseDesc::HenyeyGreenstein { g },
        lookup: Default::default(),
        storage: Default::default(),
    }
}

/// A lat-long sky of 32x16 texels: sky, ground and a broad sun (1/e radius 0.4 rad), bright
/// enough to carry a large part of the light yet wide enough that path tracing finds it often, so
/// that the two estimators can be compared at a modest sample count.
pub fn broad_sun_sky() -> EnvironmentDesc {
    let sky = Sky {
        width: 32,
        height: 16,
        zenith: [0.2, 0.35, 0.7],
        horizon: [0.7, 0.75, 0.8],
        ground: [0.15, 0.1, 0.05],
        sun: [4.0, 3.5, 2.5],
        sun_elevation: 35.0,
        sun_radius: 0.4,
    };
    EnvironmentDesc::LatLong(LatLongDesc {
        width: sky.width,
        height: sky.height,
        rgb: sky.texels(),
        to_world: IDENTITY,
        scale: 1.0,
        rows: LatLongRows::PoleToPole,
    })
}

const IDENTITY: Matrix4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// `medium` in [`UNIT`] behind an index-matched boundary (next-event estimation needs one), lit by
/// `environment`, seen by a `size` x `size` camera whose every pixel sees the box (a 10 degree
/// view of it from 3.5 units away, where the box spans more than 16 degrees): no background pixel
/// dilutes a bias in the medium's light.
pub fn framed_scene(
    size: u32,
    medium: MediumDesc,
    environment: EnvironmentDesc,
) -> SceneDescription {
    let mut desc = crate::cube_scene(size, size, medium, BsdfDesc::Null, 1.0);
    desc.camera.fov_degrees = 10.0;
    desc.environment = environment;
    desc
}
