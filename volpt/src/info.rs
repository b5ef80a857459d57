//! What a scene loads to, in words: `volpt info`'s lines, and `Scene.info()` in Python, as one
//! list of fields.

use std::fmt::{self, Write};

use volpt_core::{Estimator, PathSettings};
use volpt_render::factory::{
    default_majorants, tracking_cost, Derived, Effects, EnvironmentKind, MajorantChoice,
    MajorantRule, Parts,
};
use volpt_scene::{GridDesc, SampleLayout, SceneDescription};

/// A scene described field by field, in `volpt info`'s order: `scene`, `variant`, `film`,
/// `camera`, `integrator`, `bounds`, `shape`, `boundary`, `density`, `majorant`, `tracking`, `estimator`,
/// `albedo`, `memory` (only with grids), `lookup` (only with grids), `math`, `phase`, `light`. A
/// value of several lines (the variant's specialisations, the
/// tracking's default rule) has them separated by `\n`. [`fmt::Display`] writes `volpt info`'s
/// text: each key in a column of 11 characters, later lines of a value indented to it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Info {
    pub fields: Vec<(&'static str, String)>,
}

impl Info {
    /// The value of field `key`.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.fields
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| v.as_str())
    }
}

impl fmt::Display for Info {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (key, value) in &self.fields {
            let mut lines = value.split('\n');
            writeln!(f, "{key:<10} {}", lines.next().unwrap_or_default())?;
            for line in lines {
                writeln!(f, "{:11}{line}", "")?;
            }
        }
        Ok(())
    }
}

/// The scene `desc` from `source`, rendered with `effects` and `settings`, described.
pub fn describe(
    source: &str,
    desc: &SceneDescription,
    effects: Effects,
    settings: &PathSettings,
) -> Info {
    let mut fields = Vec::new();
    let mut field = |key: &'static str, value: String| fields.push((key, value));
    let b = &desc.boundary.bounds;
    let m = &desc.medium;
    field("scene", source.to_owned());
    let parts = Parts::of(desc, effects);
    let mut variant = parts.variant().to_string();
    if effects == Effects::General {
        variant.push_str("\n(--general: every axis at its most general part)");
    }
    for rule in &parts.simplifications {
        let _ = write!(variant, "\nspecialised: {rule}");
    }
    field("variant", variant);
    field(
        "film",
        format!("{}x{}, {} spp", desc.film.width, desc.film.height, desc.spp),
    );
    let origin = [
        desc.camera.to_world[0][3],
        desc.camera.to_world[1][3],
        desc.camera.to_world[2][3],
    ];
    field(
        "camera",
        match desc.camera.projection {
            volpt_scene::description::Projection::Perspective => format!(
                "origin {origin:?}, fov {} deg along {:?}",
                desc.camera.fov_degrees, desc.camera.fov_axis
            ),
            volpt_scene::description::Projection::Orthographic => {
                format!("orthographic, film centre {origin:?}")
            }
        },
    );
    let depth = |d: Option<u32>| d.map_or("unlimited".to_owned(), |d| d.to_string());
    field(
        "integrator",
        format!(
            "volpath, max depth {}, roulette from depth {}",
            depth(desc.integrator.max_depth),
            depth(desc.integrator.rr_depth)
        ),
    );
    field("bounds", format!("{:?} .. {:?}", b.min, b.max));
    field(
        "shape",
        match &desc.boundary.mesh {
            None => "box: one slab test per crossing".to_owned(),
            Some(mesh) => format!(
                "closed triangle mesh from {}: {} triangles, BVH of {} nodes (bounds: its \
                 bounding box); one ray cast per crossing; on the GPU by the mesh kernels \
                 ({}; homogeneous and dense-grid media)",
                mesh.source,
                mesh.triangle_count(),
                mesh.buffers.nodes.len(),
                volpt_cuda::entry::strategy_names(volpt_device::KernelSet::Mesh)
            ),
        },
    );
    if let Some(mesh) = &desc.boundary.mesh {
        field(
            "normals",
            if mesh.buffers.normals.is_empty() {
                "each triangle's own (face normals)".to_owned()
            } else {
                "interpolated vertex normals (Phong), on the CPU only: the GPU kernels refract at \
                 the triangles' own normals (face_normals=\"true\")"
                    .to_owned()
            },
        );
    }
    field("boundary", desc.boundary.bsdf.to_string());
    field("density", format!("{}, scale {}", m.density, m.scale));
    field(
        "majorant",
        format!("{} per unit length", m.max_extinction()),
    );
    field("tracking", tracking(desc, &parts, settings));
    field("estimator", estimator(&parts, settings).to_owned());
    field("albedo", m.albedo.to_string());
    let memory: Vec<_> = m.grids().map(|(name, g)| grid_memory(name, g)).collect();
    if !memory.is_empty() {
        field("memory", memory.join("\n"));
        field("lookup", m.lookup.info().to_owned());
    }
    field(
        "math",
        format!(
            "GPU {} (default; --math exact computes the CPU's bits), CPU exact",
            crate::backend::DEFAULT_GPU_MATH
        ),
    );
    field("phase", m.phase.to_string());
    field("light", desc.environment.to_string());
    if !desc.lights.is_empty() {
        field("lights", lights(desc, &parts));
    }
    Info { fields }
}

/// The lights besides the environment, and how paths reach them behind this boundary.
fn lights(desc: &SceneDescription, parts: &Parts<'_>) -> String {
    let lights = &desc.lights;
    let how = if parts.boundary.kind().index_matched() {
        "sampled at every scattering event by next-event estimation with ratio tracking, whatever          the estimator (a sun with an angular radius also by the phase function's escapes, MIS)"
    } else if lights.any_delta() {
        delta_behind_dielectric(parts.boundary.kind().rough())
    } else {
        "behind a dielectric boundary a sun with an angular radius is reached only by paths that          escape into its disc (path tracing: noisy for a small disc)"
    };
    format!("{lights}\n{how}")
}

/// What `volpt info` and the loader's warning say of a delta light behind a dielectric boundary
/// (`rough` or smooth).
pub(crate) fn delta_behind_dielectric(rough: bool) -> &'static str {
    if rough {
        "WARNING: the rough dielectric boundary bends every shadow ray, and volpt samples lights \
         only from inside an index-matched boundary, so a delta light (a sun of angular radius 0, \
         a point or spot light) adds nothing (Mitsuba 3 samples it where paths meet the rough \
         surface); give the boundary index-matched, or the sun an angular radius"
    } else {
        "WARNING: the smooth dielectric boundary bends every shadow ray, so a delta light (a sun \
         of angular radius 0, a point or spot light) adds nothing inside it (Mitsuba 3 renders \
         the same, silently: its shadow rays stop at the surface); give the boundary \
         index-matched, or the sun an angular radius"
    }
}

/// The majorants delta and ratio tracking use, and what they cost along camera rays.
fn tracking(desc: &SceneDescription, parts: &Parts<'_>, settings: &PathSettings) -> String {
    if parts.medium.kind().homogeneous() {
        return "homogeneous: every tentative collision is real".to_owned();
    }
    let bounds = &desc.boundary.bounds;
    // The majorant grid covers the boundary's box, a mesh's bounding box.
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
        "{cost}\ndefault: {}",
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
    let boundary = parts.boundary.kind();
    match (
        settings.estimator,
        boundary.index_matched(),
        boundary.rough(),
    ) {
        (_, false, false) => {
            "path tracing: the smooth dielectric boundary reflects and refracts, so no straight \
             shadow ray reaches the environment (next-event estimation needs an index-matched or a \
             rough boundary)"
        }
        (_, false, true) if parts.environment.kind() == EnvironmentKind::Constant => {
            "path tracing: a path leaving the rough boundary by the BSDF's sample sees a constant \
             environment as well as a light sample would (next-event estimation there samples maps)"
        }
        (Estimator::NextEvent, false, true) => {
            "next-event estimation of the environment where paths meet the rough boundary (MIS \
             with the BSDF; behind it no straight shadow ray reaches the environment)"
        }
        (Estimator::PathTracing, false, true) => {
            "path tracing (--estimator nee samples the map at the rough boundary)"
        }
        (Estimator::NextEvent, true, _) => {
            "next-event estimation of the environment (ratio tracking, MIS with the phase function)"
        }
        (Estimator::PathTracing, true, _) => {
            if parts.environment.kind() == EnvironmentKind::Constant {
                "path tracing (next-event estimation of a constant environment costs more than its \
                 lower variance saves; --estimator nee)"
            } else {
                "path tracing (--estimator nee samples the map)"
            }
        }
    }
}

/// What a grid takes in memory: stored, and dense where it is sparse (a VDB kept sparse).
fn grid_memory(name: &str, g: &GridDesc) -> String {
    let mib = |bytes: u64| format!("{:.2} MiB", bytes as f64 / f64::from(1 << 20));
    let stored = g.stored_bytes();
    match g.layout {
        SampleLayout::Dense => format!("{name} grid {} dense", mib(stored)),
        SampleLayout::Sparse => {
            let bricks = g.samples().len() / (512 * g.channels.max(1) as usize);
            let table = volpt_scene::sparse::box_bricks(g.resolution).unwrap_or(0);
            let dense = g
                .dense_bytes()
                .map_or("more than 2^64 bytes".to_owned(), mib);
            format!(
                "{name} grid {} sparse ({bricks} stored bricks of {table}), dense {dense}",
                mib(stored)
            )
        }
    }
}
