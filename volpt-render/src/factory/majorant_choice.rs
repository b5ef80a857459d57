//! The default majorant: one global majorant or a majorant grid, chosen by what tracking costs
//! along camera rays (a cost model, not a measurement).

use super::*;

/// What tracking costs along camera rays, per real collision: the integrals of the majorant and of
/// the extinction, and the majorant-grid cells entered, summed over a 16 x 16 fan of rays through
/// the film between their entry into the box and their exit (256 points each for the integrals, the
/// DDA's own walk for the cells).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackingCost {
    /// Tentative collisions per real one with the scene's majorants (delta tracking takes this
    /// many): the majorant's integral over the extinction's.
    pub majorant_ratio: f64,
    /// The same under the one global majorant.
    pub global_ratio: f64,
    /// Majorant-grid cells entered per real collision; 0 with the global majorant.
    pub crossings_ratio: f64,
    /// Whether the medium tracks with a majorant grid (the factory drops one that saves nothing).
    pub grid: bool,
}

impl TrackingCost {
    /// A cell crossing costs about what a tentative collision does: both draw a random number and
    /// a logarithm (sampling restarts at each cell boundary) and read a majorant or a density.
    pub const CROSSING_COST: f64 = 1.0;

    /// Work per real collision, in tentative collisions.
    pub fn per_collision(&self) -> f64 {
        self.majorant_ratio + Self::CROSSING_COST * self.crossings_ratio
    }
}

/// [`TrackingCost`] of `desc` under `settings`' majorants, or `None` when the camera rays see no
/// extinction.
pub fn tracking_cost(desc: &SceneDescription, settings: PathSettings) -> Option<TrackingCost> {
    struct Cost;
    impl SceneVisitor for Cost {
        type Output = Option<TrackingCost>;
        fn visit<S: RenderScene>(self, scene: &S) -> Self::Output {
            use volpt_core::majorant::Dda;
            use volpt_core::Medium;
            const FAN: u32 = 16;
            const POINTS: u32 = 256;
            let camera = scene.camera();
            let medium = scene.medium();
            let (mut majorant, mut global, mut extinction) = (0.0f64, 0.0f64, 0.0f64);
            let mut crossings = 0u64;
            for j in 0..FAN {
                for i in 0..FAN {
                    let px = ((i as f32 + 0.5) / FAN as f32 * camera.width as f32) as u32;
                    let py = ((j as f32 + 0.5) / FAN as f32 * camera.height as f32) as u32;
                    let ray = camera.generate_ray(px, py, Vec2::splat(0.5));
                    let bounds = scene.bounds();
                    let start = if bounds.contains(ray.origin) {
                        0.0
                    } else {
                        match bounds.entry(&ray) {
                            Some(hit) => hit.t,
                            None => continue,
                        }
                    };
                    let inside = volpt_core::Ray::new(ray.at(start), ray.dir);
                    let length = bounds.exit(&inside).t;
                    let dt = (length / POINTS as f32) as f64;
                    for k in 0..POINTS {
                        let p = inside.at((k as f32 + 0.5) / POINTS as f32 * length);
                        let bound = medium
                            .majorant_grid()
                            .map_or(medium.majorant(), |g| g.at_point(p));
                        majorant += bound as f64 * dt;
                        global += medium.majorant() as f64 * dt;
                        extinction += medium.sigma_t(p) as f64 * dt;
                    }
                    if let Some(grid) = medium.majorant_grid() {
                        let mut dda = Dda::new(grid, &inside);
                        while dda.segment(grid).1 < length {
                            dda.advance(grid, inside.dir);
                            crossings += 1;
                        }
                    }
                }
            }
            (extinction > 0.0).then(|| TrackingCost {
                majorant_ratio: majorant / extinction,
                global_ratio: global / extinction,
                crossings_ratio: crossings as f64 / extinction,
                grid: medium.majorant_grid().is_some(),
            })
        }
    }
    with_scene(desc, settings, Cost)
}

/// Why the factory tracks with the majorants it does ([`default_majorants`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MajorantRule {
    /// The extinction is one value everywhere: every tentative collision is real.
    Homogeneous,
    /// The camera rays see no extinction to weigh the majorants with.
    NoExtinction,
    /// No grid has a cell below the global bound (a uniform density, as ad's and cgg-logo's).
    NoTighterGrid,
    /// The cheapest grid's work per real collision is at most `1 / GRID_MARGIN` of the global
    /// majorant's.
    GridSavesEnough,
    /// The cheapest grid's work per real collision is more than `1 / GRID_MARGIN` of the global
    /// majorant's (or more than the global majorant's).
    GridSavesTooLittle,
}

/// The majorant resolution the factory chooses for a scene (1: the global majorant), the rule that
/// fired, and its input: the [`TrackingCost::per_collision`] of the global majorant (resolution 1)
/// and of each grid tried.
#[derive(Clone, Debug, PartialEq)]
pub struct MajorantChoice {
    pub resolution: u32,
    pub rule: MajorantRule,
    pub costs: Vec<(u32, f64)>,
}

impl MajorantChoice {
    /// Resolutions tried, cells along the box's longest axis, finest first.
    pub const RESOLUTIONS: [u32; 4] = [64, 32, 16, 8];
    /// How much cheaper than the global majorant a grid must look, per [`TrackingCost`], to be
    /// chosen. The cost model counts tracking work only, and the rest of a path (the walk's
    /// bookkeeping; on a GPU, threads of a warp in different cells) favours the global majorant:
    /// on an H100 bucky's grid of 32 (7.61 against 6.5 per real collision here) was 1.25x slower,
    /// smoke's (88.35 against 7.22) 5.4x faster (`docs/heterogeneous.md`).
    pub const GRID_MARGIN: f64 = 2.0;
}

/// The default majorants of `desc`: the resolution among [`MajorantChoice::RESOLUTIONS`] with the
/// least tracking work per real collision along camera rays ([`TrackingCost::per_collision`]), if
/// it is at most `1 / GRID_MARGIN` of the global majorant's; else the global majorant.
pub fn default_majorants(desc: &SceneDescription) -> MajorantChoice {
    let choice = |resolution, rule, costs| MajorantChoice {
        resolution,
        rule,
        costs,
    };
    let medium = Parts::of(desc, Effects::Specialised).medium.kind();
    if medium.homogeneous() {
        return choice(1, MajorantRule::Homogeneous, Vec::new());
    }
    let cost = |resolution| {
        let settings = PathSettings {
            majorant_resolution: resolution,
            estimator: Estimator::PathTracing,
            ..PathSettings::default()
        };
        tracking_cost(desc, settings)
    };
    let Some(global) = cost(1).map(|c| c.per_collision()) else {
        return choice(1, MajorantRule::NoExtinction, Vec::new());
    };
    let mut costs = vec![(1, global)];
    for resolution in MajorantChoice::RESOLUTIONS {
        // A grid no cell of which is below the global bound is dropped (`Derived::of`); then every
        // coarser grid, whose cells hold the finer cells' maxima, is dropped too.
        match cost(resolution) {
            Some(c) if c.grid => costs.push((resolution, c.per_collision())),
            _ => break,
        }
    }
    let (best, best_cost) = costs
        .iter()
        .copied()
        .fold((1, global), |a, b| if b.1 < a.1 { b } else { a });
    if costs.len() == 1 {
        choice(1, MajorantRule::NoTighterGrid, costs)
    } else if best_cost * MajorantChoice::GRID_MARGIN <= global {
        choice(best, MajorantRule::GridSavesEnough, costs)
    } else {
        choice(1, MajorantRule::GridSavesTooLittle, costs)
    }
}
