//! The real predictor: a print's appearance from straight above, rendered by volpt (any backend
//! the facade opens: the CPU, a GPU, several GPUs).
//!
//! **Scene.** The print is the medium's box, voxel `(x, y, z)` the grid cell at
//! `[x, x + 1] * sx` by `[y, y + 1] * sy` by `[z, z + 1] * sz` (nearest lookup: a voxel is one
//! material), its top surface at `z = depth * sz`. The boundary is the resin's surface
//! ([`RenderPredictor::boundary`]: a smooth dielectric of IOR 1.5 by default, or index-matched);
//! the illumination a constant environment of radiance 1 from every direction (what the print
//! reflects and transmits of uniform white light; a print standing on a black table would have a
//! black lower hemisphere: not offered yet). Paths are unlimited in length with Russian roulette
//! from depth 5 (Mitsuba's defaults).
//!
//! **Camera.** One pixel per surface texel, looking straight down: Mitsuba's `orthographic`
//! sensor over the print's top face, its film spanning the face exactly, whatever the texels'
//! aspect.
//!
//! **Chromatic extinction.** The inks' extinction differs between R, G and B, which volpt's grid
//! media do not carry yet (material-indexed volumes, issue 38, will); the prediction is rendered
//! instead as three grey media, channel `c` with extinction `sigma_t[c]` and albedo
//! `sigma_s[c] / sigma_t[c]` per voxel, taking channel `c` of each. That is exact in
//! expectation: each channel of a chromatic render equals the grey render made with that
//! channel's coefficients (the per-channel identity the materials issue tests). The scene is
//! built once per print geometry; later predictions replace its grids ([`volpt::Scene::set_grid`]),
//! so the backend re-uploads exactly what changed.
//!
//! **Noise.** Each prediction is an unbiased render of `spp` samples per texel and channel, made
//! as two independent halves (seeds `seed` and `seed + 1`, the same each time: one print always
//! predicts the same image). The halves' difference estimates each texel's standard error,
//! `|a - b| / 2` per channel (the mean of two equal-variance estimates has variance
//! `E[(a - b)^2] / 4`), kept as [`RenderPredictor::standard_error`]: the update moves an aim by
//! `step` times the prediction's error, so a standard error well below the error the loop is
//! removing is what "enough samples" means.

use thiserror::Error;
use volpt::scene_files::{
    AlbedoDesc, BoundaryDesc, Bounds, BsdfDesc, CameraDesc, DensityDesc, EnvironmentDesc, FilmDesc,
    FovAxis, GridConvention, GridDesc, GridLookup, GridStorage, IntegratorDesc, MediumDesc,
    PhaseDesc, Projection, SampleLayout, SceneBuilder, SceneDescription, SceneError,
};
use volpt::{Backend, Quiet, RenderRequest, RenderSettings, Scene};

use crate::colour::LinearRgb;
use crate::compensate::Predictor;
use crate::print::VoxelPrint;

#[derive(Debug, Error)]
pub enum PredictError {
    #[error(transparent)]
    Volpt(#[from] volpt::Error),
    #[error("the print: {field}: expected {expected}, found {found}")]
    Print {
        field: &'static str,
        expected: String,
        found: String,
    },
}

/// Renders prints from above with volpt (see the module docs).
pub struct RenderPredictor {
    backend: Backend,
    /// Samples per texel and channel.
    pub spp: u32,
    pub seed: u32,
    /// The resin's surface.
    pub boundary: BsdfDesc,
    /// The scene of the last print's geometry, whose grids the next prediction replaces.
    scene: Option<(Geometry, Scene)>,
    standard_error: Vec<LinearRgb>,
}

/// What fixes a prediction's scene apart from its grids' values.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Geometry {
    resolution: [u32; 3],
    voxel_size: [f64; 3],
    g: f32,
    boundary: BsdfDesc,
    spp: u32,
}

impl RenderPredictor {
    /// A predictor rendering on `backend` with `spp` samples per texel and channel, a smooth
    /// dielectric surface of IOR 1.5 (the order of the photopolymer resins') in air.
    pub fn new(backend: Backend, spp: u32) -> Self {
        RenderPredictor {
            backend,
            spp,
            seed: 0,
            boundary: BsdfDesc::Dielectric {
                int_ior: 1.5,
                ext_ior: 1.0,
            },
            scene: None,
            standard_error: Vec::new(),
        }
    }

    /// The last prediction's standard error per texel and channel, estimated from its two
    /// independent halves (see the module docs).
    pub fn standard_error(&self) -> &[LinearRgb] {
        &self.standard_error
    }

    fn geometry(&self, print: &VoxelPrint) -> Result<Geometry, PredictError> {
        let g = print.materials()[0].g;
        if let Some(m) = print.materials().iter().find(|m| m.g != g) {
            return Err(PredictError::Print {
                field: "materials.g",
                expected: format!("one g for every material (the first's, {g})"),
                found: format!("{} for {}", m.g, m.name),
            });
        }
        Ok(Geometry {
            resolution: print.resolution(),
            voxel_size: print.voxel_size(),
            g,
            boundary: self.boundary,
            spp: self.spp,
        })
    }
}

/// Channel `c`'s extinction grid and albedo grid (RGB, grey) of a print.
fn channel_grids(print: &VoxelPrint, c: usize) -> (Vec<f32>, Vec<f32>) {
    let per_material: Vec<(f32, f32)> = print
        .materials()
        .iter()
        .map(|m| {
            let t = m.sigma_s[c] + m.sigma_a[c];
            (t, if t > 0.0 { m.sigma_s[c] / t } else { 0.0 })
        })
        .collect();
    let density = print
        .indices()
        .iter()
        .map(|&k| per_material[usize::from(k)].0)
        .collect();
    let albedo = print
        .indices()
        .iter()
        .flat_map(|&k| [per_material[usize::from(k)].1; 3])
        .collect();
    (density, albedo)
}

/// The scene of a print's channel, built in code.
struct PrintScene<'a> {
    print: &'a VoxelPrint,
    geometry: Geometry,
}

impl SceneBuilder for PrintScene<'_> {
    fn source(&self) -> String {
        "volpt-print's top view of a voxel print".into()
    }

    fn build(&self, _params: &[(String, String)]) -> Result<SceneDescription, SceneError> {
        let [w, h, d] = self.geometry.resolution;
        let [sx, sy, sz] = self.geometry.voxel_size;
        let size = [f64::from(w) * sx, f64::from(h) * sy, f64::from(d) * sz];
        let bounds = Bounds {
            min: [0.0; 3],
            max: size.map(|s| s as f32),
        };
        let (density, albedo) = channel_grids(self.print, 0);
        let grid = |channels, data| GridDesc {
            resolution: self.geometry.resolution,
            channels,
            bounds,
            convention: GridConvention::Cell,
            data,
            layout: SampleLayout::Dense,
        };
        // Mitsuba's camera frame, columns left, up, view direction and origin: looking down -z
        // with +y up puts +x to the image's right and +y at its top. The orthographic film spans
        // camera-space x in [-1, 1] and y in [-h/w, h/w]: scaling x by half the print's width and
        // y by w/h times half its height maps the film onto the top face, one pixel per texel.
        let aspect = f64::from(w) / f64::from(h);
        let half = [0.5 * size[0], 0.5 * size[1] * aspect];
        let above = size[2] + sz;
        let to_world = [
            [-half[0] as f32, 0.0, 0.0, (0.5 * size[0]) as f32],
            [0.0, half[1] as f32, 0.0, (0.5 * size[1]) as f32],
            [0.0, 0.0, -1.0, above as f32],
            [0.0, 0.0, 0.0, 1.0],
        ];
        Ok(SceneDescription {
            camera: CameraDesc {
                to_world,
                // Unused by an orthographic camera.
                fov_degrees: 0.0,
                fov_axis: FovAxis::X,
                projection: Projection::Orthographic,
            },
            film: FilmDesc {
                width: w,
                height: h,
            },
            spp: self.geometry.spp,
            integrator: IntegratorDesc {
                max_depth: None,
                rr_depth: Some(5),
            },
            boundary: BoundaryDesc {
                bounds,
                bsdf: self.geometry.boundary,
            },
            medium: MediumDesc {
                density: DensityDesc::Grid(grid(1, density)),
                scale: 1.0,
                albedo: AlbedoDesc::Grid(grid(3, albedo)),
                phase: if self.geometry.g == 0.0 {
                    PhaseDesc::Isotropic
                } else {
                    PhaseDesc::HenyeyGreenstein { g: self.geometry.g }
                },
                lookup: GridLookup::Nearest,
                storage: GridStorage::Dense,
            },
            environment: EnvironmentDesc::Constant([1.0; 3]),
        })
    }
}

impl Predictor for RenderPredictor {
    type Error = PredictError;

    fn predict(&mut self, print: &VoxelPrint) -> Result<Vec<LinearRgb>, PredictError> {
        let geometry = self.geometry(print)?;
        if self.scene.as_ref().is_none_or(|(g, _)| *g != geometry) {
            let builder = PrintScene { print, geometry };
            // Nearest lookup chosen, not left to the backend's default (a voxel is one material).
            let settings = RenderSettings {
                lookup: Some(GridLookup::Nearest),
                ..RenderSettings::default()
            };
            self.scene = Some((geometry, Scene::build(&builder, &settings)?));
        }
        let (_, scene) = self.scene.as_mut().expect("built above");
        let [w, h, _] = geometry.resolution;
        let mut texels = vec![LinearRgb([0.0; 3]); w as usize * h as usize];
        let mut errors = texels.clone();
        for c in 0..3 {
            let (density, albedo) = channel_grids(print, c);
            scene.set_grid("density", density)?;
            scene.set_grid("albedo", albedo)?;
            // Two independent halves (spp / 2 and the rest), averaged by their sample counts.
            let halves = [self.spp / 2, self.spp - self.spp / 2];
            let mut images = Vec::new();
            for (k, &n) in halves.iter().enumerate() {
                if n == 0 {
                    continue;
                }
                let mut film = scene.film();
                let request = RenderRequest::samples(0..n)
                    .with_seed(self.seed.wrapping_add(k as u32))
                    .with_lookup(GridLookup::Nearest);
                self.backend.render(scene, &mut film, request, &Quiet)?;
                images.push((f64::from(n), film.image(n)));
            }
            // Image row 0 is the print's top edge, texel row h - 1.
            for y in 0..h {
                for x in 0..w {
                    let at = |image: &volpt::Image| f64::from(image.pixel(x, h - 1 - y)[c]);
                    let i = (x + w * y) as usize;
                    let total: f64 = images.iter().map(|(n, _)| n).sum();
                    texels[i].0[c] = images.iter().map(|(n, im)| n * at(im)).sum::<f64>() / total;
                    errors[i].0[c] = match images.as_slice() {
                        [(_, a), (_, b)] => 0.5 * (at(a) - at(b)).abs(),
                        _ => f64::INFINITY,
                    };
                }
            }
        }
        self.standard_error = errors;
        Ok(texels)
    }
}
