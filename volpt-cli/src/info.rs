//! `volpt info`: what a scene loads to, in words.

use std::fmt::Write;
use std::path::Path;

use volpt_core::{Estimator, PathSettings};
use volpt_render::factory::{
    default_majorants, tracking_cost, BoundaryKind, Derived, Effects, EnvironmentKind,
    MajorantChoice, MajorantRule, MediumKind, Parts,
};
use volpt_scene::{
    AlbedoDesc, BsdfDesc, DensityDesc, EnvironmentDesc, GridDesc, PhaseDesc, SceneDescription,
};

pub fn describe(
    path: &Path,
    desc: &SceneDescription,
    effects: Effects,
    settings: &PathSettings,
) -> String {
    let mut s = String::new();
    let b = &desc.boundary.bounds;
    let m = &desc.medium;
    let _ = writeln!(s, "scene      {}", path.display());
    let parts = Parts::of(desc, effects);
    let _ = writeln!(s, "variant    {}", parts.variant());
    if effects == Effects::General {
        let _ = writeln!(
            s,
            "           (--general: every axis at its most general part)"
        );
    }
    for rule in &parts.simplifications {
        let _ = writeln!(s, "           specialised: {rule}");
    }
    let _ = writeln!(
        s,
        "film       {}x{}, {} spp",
        desc.film.width, desc.film.height, desc.spp
    );
    let _ = writeln!(
        s,
        "camera     origin {:?}, fov {} deg along {:?}",
        [
            desc.camera.to_world[0][3],
            desc.camera.to_world[1][3],
            desc.camera.to_world[2][3]
        ],
        desc.camera.fov_degrees,
        desc.camera.fov_axis
    );
    let depth = |d: Option<u32>| d.map_or("unlimited".to_owned(), |d| d.to_string());
    let _ = writeln!(
        s,
        "integrator volpath, max depth {}, roulette from depth {}",
        depth(desc.integrator.max_depth),
        depth(desc.integrator.rr_depth)
    );
    let _ = writeln!(s, "bounds     {:?} .. {:?}", b.min, b.max);
    let boundary = match desc.boundary.bsdf {
        BsdfDesc::Null => "index-matched (null)".to_owned(),
        BsdfDesc::Dielectric { int_ior, ext_ior } => {
            format!("smooth dielectric, int IOR {int_ior}, ext IOR {ext_ior}")
        }
        BsdfDesc::RoughDielectric {
            alpha,
            int_ior,
            ext_ior,
        } => format!("GGX rough dielectric, alpha {alpha}, int IOR {int_ior}, ext IOR {ext_ior}"),
    };
    let _ = writeln!(s, "boundary   {boundary}");
    let grid = |g: &GridDesc| {
        let (lo, hi) = g
            .data
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        format!(
            "grid {}x{}x{}x{}, {:?}-centred, bounds {:?} .. {:?}, values {lo} .. {hi}",
            g.resolution[0],
            g.resolution[1],
            g.resolution[2],
            g.channels,
            g.convention,
            g.bounds.min,
            g.bounds.max
        )
    };
    let (density, majorant) = match &m.density {
        DensityDesc::Constant(d) => (format!("constant {d}"), m.scale * d),
        DensityDesc::Grid(g) => (grid(g), m.scale * g.max_value()),
    };
    let _ = writeln!(s, "density    {density}, scale {}", m.scale);
    let _ = writeln!(s, "majorant   {majorant} per unit length");
    let _ = writeln!(s, "tracking   {}", tracking(desc, &parts, settings));
    let _ = writeln!(s, "estimator  {}", estimator(&parts, settings));
    let albedo = match &m.albedo {
        AlbedoDesc::Constant(rgb) => format!("constant {rgb:?}"),
        AlbedoDesc::Grid(g) => grid(g),
    };
    let _ = writeln!(s, "albedo     {albedo}");
    let phase = match m.phase {
        PhaseDesc::Isotropic => "isotropic".to_owned(),
        PhaseDesc::HenyeyGreenstein { g } => format!("Henyey-Greenstein, g {g}"),
    };
    let _ = writeln!(s, "phase      {phase}");
    let light = match &desc.environment {
        EnvironmentDesc::Constant(rgb) => format!("constant environment, radiance {rgb:?}"),
        EnvironmentDesc::LatLong(map) => format!(
            "lat-long environment map {}x{}, scale {}, rows {:?}",
            map.width, map.height, map.scale, map.rows
        ),
    };
    let _ = writeln!(s, "light      {light}");
    s
}

/// The majorants delta and ratio tracking use, and what they cost along camera rays.
fn tracking(desc: &SceneDescription, parts: &Parts<'_>, settings: &PathSettings) -> String {
    if parts.medium.kind() == MediumKind::Homogeneous {
        return "homogeneous: every tentative collision is real".to_owned();
    }
    let bounds = &desc.boundary.bounds;
    let derived = Derived::of(
        parts,
        volpt_core::Aabb::new(bounds.min.into(), bounds.max.into()),
        settings,
    );
    let how = match derived.majorant_resolution() {
        Some([x, y, z]) => format!("majorant grid {x}x{y}x{z}, DDA"),
        None if settings.majorant_resolution > 1 => {
            "one global majorant (every cell of a majorant grid would have it)".to_owned()
        }
        None => "one global majorant".to_owned(),
    };
    let cost = match tracking_cost(desc, *settings) {
        Some(c) => format!(
            "{how}; majorant / extinction along camera rays {:.2} (global majorant {:.2}), cells \
             crossed per real collision {:.2}",
            c.majorant_ratio, c.global_ratio, c.crossings_ratio
        ),
        None => format!("{how}; camera rays see no extinction"),
    };
    format!(
        "{cost}\n           default: {}",
        majorant_rule(&default_majorants(desc))
    )
}

/// The factory's choice of majorants, the rule that fired and its input.
fn majorant_rule(choice: &MajorantChoice) -> String {
    let margin = MajorantChoice::GRID_MARGIN;
    let rule = match choice.rule {
        MajorantRule::Homogeneous => return "the extinction is one value: no grid".to_owned(),
        MajorantRule::NoExtinction => {
            return "the global majorant (camera rays see no extinction to weigh a grid with)"
                .to_owned()
        }
        MajorantRule::NoTighterGrid => {
            "the global majorant: no grid has a cell below its bound".to_owned()
        }
        MajorantRule::GridSavesEnough => format!(
            "a grid of {} cells: the least work per real collision, at most 1/{margin} of the \
             global majorant's",
            choice.resolution
        ),
        MajorantRule::GridSavesTooLittle => format!(
            "the global majorant: no grid does less than 1/{margin} of its work per real collision"
        ),
    };
    let costs: Vec<String> = choice
        .costs
        .iter()
        .map(|(r, c)| match r {
            1 => format!("global {c:.2}"),
            r => format!("{r} cells {c:.2}"),
        })
        .collect();
    format!(
        "{rule} (tentative collisions + cell crossings per real collision: {}; \
         --tracking, --majorant-resolution override)",
        costs.join(", ")
    )
}

/// The estimator the paths use, and why.
fn estimator(parts: &Parts<'_>, settings: &PathSettings) -> &'static str {
    let index_matched = parts.boundary.kind() == BoundaryKind::IndexMatched;
    match (settings.estimator, index_matched) {
        (_, false) => {
            "path tracing: the dielectric boundary reflects and refracts, so no straight shadow ray \
             reaches the environment (next-event estimation needs an index-matched boundary)"
        }
        (Estimator::NextEvent, true) => {
            "next-event estimation of the environment (ratio tracking, MIS with the phase function)"
        }
        (Estimator::PathTracing, true) => {
            if parts.environment.kind() == EnvironmentKind::Constant {
                "path tracing (next-event estimation of a constant environment costs more than its \
                 lower variance saves; --estimator nee)"
            } else {
                "path tracing (--estimator nee samples the map)"
            }
        }
    }
}
