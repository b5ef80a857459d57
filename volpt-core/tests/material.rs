//! Material-indexed volumes ([`volpt_core::material`]) on scenes built by hand:
//! - a grid whose every voxel holds material k renders bit for bit as the homogeneous chromatic
//!   medium of k (its extinction, albedo and phase asymmetry: the per-collision `g` is read);
//! - through a layered slab of two materials whose channels are 5x apart, spectral ratio tracking
//!   and spectral delta tracking estimate each channel's analytic transmittance
//!   `exp(-sum_k sigma_k l_k)` (z-tests), with the global majorants, with the majorant grid's
//!   bound of every channel and with its per-channel bounds;
//! - each channel of a render of a random 4^3 grid of three materials equals the grey render of
//!   that channel's coefficients as nearest-sample grids (the per-channel identity);
//! - the majorant grid bounds every channel of every point of its cells, and each channel's own
//!   bounds bound that channel;
//! - on a table whose channels are 10^10 apart, with an empty material, every path's light is
//!   finite and non-negative and its path densities stay in [0, 3].

mod common;

use common::{Moments, TestRng, Z_MAX};
use volpt_core::grid::{AnyLayout, GridLookup};
use volpt_core::majorant::{build_majorants, MajorantGrid};
use volpt_core::material::{
    build_material_channel_majorants, build_material_majorants, Material, MATERIAL_FLOATS,
};
use volpt_core::path::{trace, Truncation};
use volpt_core::rng::Rng;
use volpt_core::tracking::{spectral_delta_tracking, spectral_ratio_tracking, FreeFlight};
use volpt_core::{
    Aabb, Bsdf, ChromaticMedium, ConstantEnvironment, Estimator, Grid, GridAlbedo, GridMapping,
    GridMedium, HenyeyGreenstein, MaterialGrid, Medium, NullBoundary, PathSettings, PathState,
    PerspectiveCamera, Ray, Scene, SmoothDielectric, Spectrum, Vec2, Vec3, VolumeScene,
};

const LIGHT: [f32; 3] = [1.0, 0.9, 0.8];

fn bounds() -> Aabb {
    Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))
}

/// A 4 x 4 film whose rays all enter the box `[-1, 1]^3` through its front face.
fn camera() -> PerspectiveCamera {
    PerspectiveCamera {
        origin: Vec3::new(0.0, 0.0, -4.0),
        axis_x: Vec3::new(-1.0, 0.0, 0.0),
        axis_y: Vec3::Y,
        axis_z: Vec3::Z,
        tan_half_fov: Vec2::new(0.15, 0.15),
        width: 4,
        height: 4,
        orthographic: false,
    }
}

fn scene<M: Medium, B: Bsdf>(
    medium: M,
    boundary: B,
    g: f32,
    estimator: Estimator,
) -> VolumeScene<M, B, HenyeyGreenstein, ConstantEnvironment> {
    VolumeScene {
        camera: camera(),
        bounds: bounds(),
        medium,
        boundary,
        phase: HenyeyGreenstein { g },
        environment: ConstantEnvironment(Spectrum::from_array(LIGHT)),
        lights: volpt_core::Lights::NONE,
        settings: PathSettings {
            estimator,
            ..Default::default()
        },
    }
}

/// Cyan, magenta and white resins of a print, roughly (coefficients per world unit; cyan absorbs
/// red 5x more than blue), each with its own asymmetry.
fn print_materials() -> [Material; 3] {
    [
        Material::from_coefficients([0.6, 1.2, 1.5], [2.5, 0.6, 0.1], 0.4),
        Material::from_coefficients([1.1, 0.5, 1.0], [0.2, 2.0, 0.3], -0.3),
        Material::from_coefficients([2.0, 2.0, 2.0], [0.05, 0.05, 0.05], 0.7),
    ]
}

fn table(materials: &[Material]) -> Vec<f32> {
    materials.iter().flat_map(|m| m.row()).collect()
}

/// One byte per voxel, four to a word, little end first.
fn pack(indices: &[u8]) -> Vec<u32> {
    indices
        .chunks(4)
        .map(|c| {
            let mut w = [0u8; 4];
            w[..c.len()].copy_from_slice(c);
            u32::from_le_bytes(w)
        })
        .collect()
}

/// Each path's radiance of `paths` paths spread over the film.
fn radiances<S: Scene>(scene: &S, paths: u32, seed: u32) -> Vec<Spectrum> {
    let (w, h) = (scene.camera().width, scene.camera().height);
    let mut out = Vec::new();
    for sample in 0..paths / (w * h) {
        for py in 0..h {
            for px in 0..w {
                let mut path = PathState::from_camera(scene, px, py, sample, seed);
                trace(scene, &mut path);
                assert_eq!(path.truncated, Truncation::None);
                out.push(path.radiance);
            }
        }
    }
    out
}

fn one_material_bit_for_bit<B: Bsdf + Copy>(boundary: B, estimator: Estimator) {
    let materials = print_materials();
    let table = table(&materials);
    let res = [3, 2, 5];
    for (k, material) in materials.iter().enumerate() {
        let indices = pack(&[k as u8; 30]);
        let grid = MaterialGrid::new(&indices, res, bounds(), &table, 1.0);
        // The scene's phase has another g: only the material's may be used.
        let indexed = scene(ChromaticMedium::indexed(grid), boundary, 0.0, estimator);
        let homogeneous = ChromaticMedium::new(material.sigma_t, None, material.albedo, None);
        let homogeneous = scene(homogeneous, boundary, material.g, estimator);
        let (a, b) = (
            radiances(&indexed, 4096, 3),
            radiances(&homogeneous, 4096, 3),
        );
        assert!(a.iter().any(|r| *r != Spectrum::ZERO));
        for (i, (a, b)) in a.iter().zip(&b).enumerate() {
            assert_eq!(
                a.to_array().map(f32::to_bits),
                b.to_array().map(f32::to_bits),
                "material {k}, path {i}: {a} vs {b}"
            );
        }
    }
}

#[test]
fn one_material_everywhere_renders_as_its_homogeneous_medium_bit_for_bit() {
    one_material_bit_for_bit(NullBoundary, Estimator::PathTracing);
    one_material_bit_for_bit(NullBoundary, Estimator::NextEvent);
    one_material_bit_for_bit(SmoothDielectric { eta: 1.5 }, Estimator::PathTracing);
}

/// A slab of material A below z = 0.5 and B above (an index grid of 1 x 1 x 4 voxels), the
/// analytic transmittance of a ray along +z through it, and the medium with the global majorant
/// or a majorant grid of `cells` along z.
struct Slab {
    indices: Vec<u32>,
    table: Vec<f32>,
    majorants: Vec<f32>,
    channels: Vec<f32>,
}

/// How [`Slab::medium`] tracks.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Tracking {
    /// Each channel's largest extinction over the volume.
    Global,
    /// A majorant grid whose cells bound every channel at once.
    Grid,
    /// A majorant grid and each channel's own bound per cell.
    ChannelGrid,
}

const SLAB_A: Material = Material {
    sigma_t: Spectrum::new(0.2, 0.5, 1.0),
    albedo: Spectrum::new(0.5, 0.5, 0.5),
    g: 0.0,
};
const SLAB_B: Material = Material {
    sigma_t: Spectrum::new(1.6, 0.4, 0.32),
    albedo: Spectrum::new(0.5, 0.5, 0.5),
    g: 0.0,
};

impl Slab {
    fn new() -> Self {
        Self {
            indices: pack(&[0, 0, 0, 1]),
            table: table(&[SLAB_A, SLAB_B]),
            majorants: vec![0.0; 8],
            channels: vec![0.0; 24],
        }
    }

    fn grid(&self) -> MaterialGrid<'_> {
        MaterialGrid::new(&self.indices, [1, 1, 4], bounds(), &self.table, 1.0)
    }

    fn medium(&mut self, tracking: Tracking) -> ChromaticMedium<'_> {
        let res = [1, 1, 8];
        let grid = MaterialGrid::new(&self.indices, [1, 1, 4], bounds(), &self.table, 1.0);
        build_material_majorants(&grid, bounds(), res, &mut self.majorants);
        build_material_channel_majorants(&grid, bounds(), res, &mut self.channels);
        // The cells of A and of B take their own material's bound (one voxel of margin).
        assert_eq!(self.majorants[0], 1.0);
        assert_eq!(self.majorants[7], 1.6);
        assert_eq!(self.channels[..3], SLAB_A.sigma_t.to_array());
        // B's last cell reads A's voxel below it too (the margin): each channel's larger.
        assert_eq!(
            self.channels[21..],
            SLAB_A.sigma_t.max(SLAB_B.sigma_t).to_array()
        );
        let mut medium = ChromaticMedium::indexed(self.grid());
        assert_eq!(medium.channel_majorant, Spectrum::new(1.6, 0.5, 1.0));
        if tracking != Tracking::Global {
            medium.majorants = Some(MajorantGrid::new(&self.majorants, res, bounds()));
        }
        if tracking == Tracking::ChannelGrid {
            medium.channel_majorants = Some(&self.channels);
        }
        medium
    }

    /// `exp(-(1.5 sigma_A + 0.5 sigma_B))` per channel: 1.5 units of A, then 0.5 of B.
    fn transmittance() -> [f64; 3] {
        [0, 1, 2]
            .map(|c| (-(1.5 * SLAB_A.sigma_t[c] as f64 + 0.5 * SLAB_B.sigma_t[c] as f64)).exp())
    }
}

/// Asserts each channel's mean is `expected` within `Z_MAX` standard errors.
fn assert_means(what: &str, moments: &[Moments; 3], expected: [f64; 3]) {
    for c in 0..3 {
        let (mean, se) = (moments[c].mean(), moments[c].std_error());
        let z = (mean - expected[c]).abs() / se;
        eprintln!(
            "{what}, channel {c}: {mean:.5} vs {:.5} (se {se:.1e}, z {z:.2})",
            expected[c]
        );
        assert!(z < Z_MAX, "{what}, channel {c}: z = {z}");
        assert!(se < 0.01 * expected[c], "{what}: too little power");
    }
}

#[test]
fn a_layered_slab_transmits_each_channel_analytically() {
    let ray = Ray::new(Vec3::new(0.3, -0.2, -1.0), Vec3::Z);
    for tracking in [Tracking::Global, Tracking::Grid, Tracking::ChannelGrid] {
        let mut slab = Slab::new();
        let medium = slab.medium(tracking);
        let (mut ratio, mut flight) = ([Moments::default(); 3], [Moments::default(); 3]);
        for i in 0..1 << 18 {
            let mut rng = Rng::new(7, i, 0);
            let mut steps = 0;
            let t = spectral_ratio_tracking(&medium, &ray, 2.0, &mut rng, &mut steps, u32::MAX)
                .expect("within the budget");
            for c in 0..3 {
                ratio[c].push(t[c] as f64);
            }
            // Spectral delta tracking: escaping weighs r_u per channel (throughput 1).
            let hero = (i % 3) as u8;
            let mut r_u = Spectrum::ONE;
            let event = spectral_delta_tracking(
                &medium,
                &ray,
                2.0,
                &mut rng,
                hero,
                &mut r_u,
                &mut steps,
                u32::MAX,
            );
            let escaped = event == FreeFlight::Escaped;
            for c in 0..3 {
                flight[c].push(if escaped { r_u[c] as f64 } else { 0.0 });
            }
        }
        let what = format!("{tracking:?}");
        assert_means(
            &format!("ratio tracking, {what}"),
            &ratio,
            Slab::transmittance(),
        );
        assert_means(
            &format!("delta tracking, {what}"),
            &flight,
            Slab::transmittance(),
        );
    }
}

/// A random 4^3 grid of the three print materials (all of asymmetry 0.3, which a grey phase
/// function can hold), its majorant grid, and each channel's nearest-sample grey grids.
#[test]
fn indexed_channels_are_grey_renders_of_their_materials() {
    const RES: [u32; 3] = [4, 4, 4];
    let materials = print_materials().map(|m| Material { g: 0.3, ..m });
    let table = table(&materials);
    let mut rng = TestRng::new(11);
    let bytes: Vec<u8> = (0..64).map(|_| (rng.next_u64() % 3) as u8).collect();
    let indices = pack(&bytes);
    let grid = MaterialGrid::new(&indices, RES, bounds(), &table, 1.0);
    let cells = [2, 2, 2];
    let mut majorants = vec![0.0; 8];
    build_material_majorants(&grid, bounds(), cells, &mut majorants);
    let mut channels = vec![0.0; 24];
    build_material_channel_majorants(&grid, bounds(), cells, &mut channels);
    let mut medium = ChromaticMedium::indexed(grid);
    medium.majorants = Some(MajorantGrid::new(&majorants, cells, bounds()));
    medium.channel_majorants = Some(&channels);
    let paths = 1 << 18;
    for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
        let chromatic = moments(&radiances(
            &scene(medium, NullBoundary, 0.3, estimator),
            paths,
            1,
        ));
        for c in 0..3 {
            let mapping = GridMapping::cell_centred(bounds(), RES);
            let density: Vec<f32> = bytes
                .iter()
                .map(|&k| materials[k as usize].sigma_t[c])
                .collect();
            let albedo: Vec<f32> = bytes
                .iter()
                .flat_map(|&k| [materials[k as usize].albedo[c]; 3])
                .collect();
            let density_grid = Grid::new(&density, RES, mapping).with_lookup(GridLookup::Nearest);
            let mut grey_majorants = vec![0.0; 8];
            build_majorants(&density_grid, 1.0, bounds(), cells, &mut grey_majorants);
            let grey = GridMedium {
                density: density_grid,
                scale: 1.0,
                majorant: density.iter().copied().fold(0.0, f32::max),
                majorants: Some(MajorantGrid::new(&grey_majorants, cells, bounds())),
                albedo: GridAlbedo(
                    Grid::new(&albedo, RES, mapping).with_lookup(GridLookup::Nearest),
                    AnyLayout,
                ),
                reads: AnyLayout,
            };
            let grey = moments(&radiances(
                &scene(grey, NullBoundary, 0.3, estimator),
                paths,
                2,
            ));
            let (a, b) = (chromatic[c], grey[c]);
            let se = (a.std_error().powi(2) + b.std_error().powi(2)).sqrt();
            let z = (a.mean() - b.mean()).abs() / se;
            eprintln!(
                "{estimator:?}, channel {c}: indexed {:.5} grey {:.5} (se {se:.1e}, z {z:.2})",
                a.mean(),
                b.mean()
            );
            assert!(z < Z_MAX, "{estimator:?}, channel {c}: z = {z}");
            assert!(se < 6e-3 * b.mean(), "too little power");
        }
    }
}

fn moments(radiances: &[Spectrum]) -> [Moments; 3] {
    let mut m = [Moments::default(); 3];
    for r in radiances {
        for c in 0..3 {
            m[c].push(r[c] as f64);
        }
    }
    m
}

#[test]
fn the_majorant_grid_bounds_every_channel_inside_its_cells() {
    const RES: [u32; 3] = [7, 5, 6];
    let mut rng = TestRng::new(3);
    let materials: Vec<Material> = (0..5)
        .map(|_| {
            let mut v = || (rng.next_u64() % 1000) as f32 / 100.0;
            Material::from_coefficients([v(), v(), v()], [v(), v(), v()], 0.0)
        })
        .collect();
    let table = table(&materials);
    let bytes: Vec<u8> = (0..210).map(|_| (rng.next_u64() % 5) as u8).collect();
    let indices = pack(&bytes);
    let grid = MaterialGrid::new(&indices, RES, bounds(), &table, 2.0);
    let cells = [3, 4, 3];
    let mut bound = vec![0.0; 36];
    build_material_majorants(&grid, bounds(), cells, &mut bound);
    let majorants = MajorantGrid::new(&bound, cells, bounds());
    // Materials in slabs along x: the cells of the slabs without the densest material are
    // tighter than the global bound (the grid saves steps).
    let slabs: Vec<u8> = (0..210).map(|i| (i % 7 * 5 / 7) as u8).collect();
    let slab_indices = pack(&slabs);
    let slab_grid = MaterialGrid::new(&slab_indices, RES, bounds(), &table, 2.0);
    let densest = (0..5)
        .max_by(|&a, &b| {
            materials[a]
                .sigma_t
                .max_element()
                .total_cmp(&materials[b].sigma_t.max_element())
        })
        .unwrap();
    let mut slab_bound = vec![0.0; 36];
    build_material_majorants(&slab_grid, bounds(), cells, &mut slab_bound);
    let lightest_cell = slab_bound.iter().copied().fold(f32::INFINITY, f32::min);
    assert!(
        lightest_cell < slab_grid.max_extinction(),
        "densest material {densest}: {slab_bound:?}"
    );
    for _ in 0..200_000 {
        let mut u = || (rng.next_u64() >> 11) as f32 / (1u64 << 53) as f32 * 2.0 - 1.0;
        let p = Vec3::new(u(), u(), u());
        let sigma = grid.sigma_t(p);
        assert!(
            sigma.max_element() <= majorants.at_point(p),
            "{p}: {sigma} > {}",
            majorants.at_point(p)
        );
    }
    // Each channel's own bounds, on both grids: the largest is the bound of every channel, each
    // bounds its channel at every point of its cell, and on the slabs some are tighter.
    for grid in [grid, slab_grid] {
        let mut bound = vec![0.0; 36];
        build_material_majorants(&grid, bounds(), cells, &mut bound);
        let mut channels = vec![0.0; 3 * 36];
        build_material_channel_majorants(&grid, bounds(), cells, &mut channels);
        for (b, c) in bound.iter().zip(channels.chunks(3)) {
            assert_eq!(*b, c[0].max(c[1]).max(c[2]));
        }
        let medium = ChromaticMedium {
            majorants: Some(MajorantGrid::new(&bound, cells, bounds())),
            channel_majorants: Some(&channels),
            ..ChromaticMedium::indexed(grid)
        };
        for _ in 0..200_000 {
            let mut u = || (rng.next_u64() >> 11) as f32 / (1u64 << 53) as f32 * 2.0 - 1.0;
            let p = Vec3::new(u(), u(), u());
            let sigma = grid.sigma_t(p);
            let q = (p - bounds().min) / bounds().extent();
            let cell = |a: usize| ((q[a] * cells[a] as f32) as u32).min(cells[a] - 1);
            let index = ((cell(2) * cells[1] + cell(1)) * cells[0] + cell(0)) as usize;
            let own = medium.majorant_rgb(bound[index], Some(index));
            assert!(sigma.cmple(own).all(), "{p}: {sigma} > {own}");
        }
    }
    let mut slab_channels = vec![0.0; 3 * 36];
    build_material_channel_majorants(&slab_grid, bounds(), cells, &mut slab_channels);
    assert!(slab_channels
        .chunks(3)
        .zip(&slab_bound)
        .any(|(c, b)| c.iter().any(|v| v < b)));
    // Without a grid each channel's bound is its largest over the materials present.
    let global = ChromaticMedium::indexed(grid).majorant_rgb(grid.max_extinction(), None);
    assert_eq!(global.max_element(), grid.max_extinction());
    for (k, material) in materials.iter().enumerate() {
        if bytes.contains(&(k as u8)) {
            assert!((material.sigma_t * 2.0).cmple(global).all());
        }
    }
}

#[test]
fn extreme_tables_give_finite_light_and_bounded_path_densities() {
    let materials = [
        Material::from_coefficients([1e-6, 1.0, 1e4], [0.0, 0.0, 1e-3], 0.5),
        Material::from_coefficients([1e4, 1e-6, 1.0], [1.0, 0.0, 0.0], -0.5),
        Material::from_coefficients([0.0; 3], [0.0; 3], 0.0),
    ];
    assert_eq!(materials[2].albedo, Spectrum::ZERO);
    let table = table(&materials);
    let bytes: Vec<u8> = (0..27).map(|i| (i * 7 % 3) as u8).collect();
    let indices = pack(&bytes);
    let grid = MaterialGrid::new(&indices, [3, 3, 3], bounds(), &table, 1.0);
    let mut majorants = vec![0.0; 27];
    build_material_majorants(&grid, bounds(), [3, 3, 3], &mut majorants);
    let mut channels = vec![0.0; 81];
    build_material_channel_majorants(&grid, bounds(), [3, 3, 3], &mut channels);
    let global = ChromaticMedium::indexed(grid);
    let mut with_grid = global;
    with_grid.majorants = Some(MajorantGrid::new(&majorants, [3, 3, 3], bounds()));
    let mut with_channels = with_grid;
    with_channels.channel_majorants = Some(&channels);
    for (medium, estimator) in [global, with_grid, with_channels]
        .into_iter()
        .flat_map(|m| [(m, Estimator::PathTracing), (m, Estimator::NextEvent)])
    {
        let scene = scene(medium, NullBoundary, 0.0, estimator);
        for sample in 0..700 {
            let mut path = PathState::from_camera(&scene, 1, 2, sample, 9);
            while path.alive {
                volpt_core::path::step(&scene, &mut path);
                let r = path.spectral.r_u;
                assert!(r.is_finite() && r.min_element() >= 0.0 && r.max_element() <= 3.0);
            }
            let light = path.radiance;
            assert!(light.is_finite() && light.min_element() >= 0.0, "{light}");
        }
    }
    // The table's rows hold what the core reads.
    assert_eq!(table.len(), 3 * MATERIAL_FLOATS);
}
