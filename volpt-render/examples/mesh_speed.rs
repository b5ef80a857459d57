//! A scene's box boundary against the same box as a 12-triangle mesh (each as the factory holds
//! it, a [`BoundaryShape`]; the mesh with its distance grid), on the CPU, same run: segments per
//! second of each (alternating, three rounds), whether the images agree bit for bit (the mesh of
//! a box traces the box's paths), and the fraction of free flights inside the mesh that still cast
//! a ray through its BVH (counted in a fourth, untimed render).
//!
//!     cargo run --release -p volpt-render --example mesh_speed -- scenes/homogeneous-cube/scene.xml 4 64
//!
//! A fourth argument sets the distance grid's cells along the box's longest axis (default: what
//! the scene loaders build, `DISTANCE_RESOLUTION`).

use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

use volpt_core::flight::{FlightEnd, LazyExit};
use volpt_core::geometry::BoxHit;
use volpt_core::mesh::build::build;
use volpt_core::mesh::distance::{resolution_for, DISTANCE_RESOLUTION};
use volpt_core::mesh::primitives::cuboid;
use volpt_core::{Aabb, BoundaryShape, Ray, Shape, Vec3, WithShape};
use volpt_render::{path_settings, render, with_scene, RenderOptions, RenderScene, SceneVisitor};
use volpt_scene::{builder_for, Config, SceneAssembler};

static FLIGHTS: AtomicU64 = AtomicU64::new(0);
static CASTS: AtomicU64 = AtomicU64::new(0);

/// A shape that counts its free flights and the ray casts they make.
struct Counting<'a>(BoundaryShape<'a>);

#[derive(Clone, Copy)]
struct CountingExit<'a> {
    exit: LazyExit<'a>,
    counted: bool,
}

impl CountingExit<'_> {
    fn note(&mut self) {
        if !self.counted && self.exit.was_cast() {
            self.counted = true;
            CASTS.fetch_add(1, Ordering::Relaxed);
        }
    }
}

impl FlightEnd for CountingExit<'_> {
    fn reached(&mut self, t: f32) -> bool {
        let r = self.exit.reached(t);
        self.note();
        r
    }
    fn before(&mut self, t: f32) -> bool {
        let r = self.exit.before(t);
        self.note();
        r
    }
    fn clip(&mut self, t: f32) -> f32 {
        let r = self.exit.clip(t);
        self.note();
        r
    }
    fn exact(&mut self) -> f32 {
        let r = self.exit.exact();
        self.note();
        r
    }
}

impl Shape for Counting<'_> {
    const CONVEX: bool = false;
    type Exit<'e>
        = CountingExit<'e>
    where
        Self: 'e;

    fn convex(&self) -> bool {
        self.0.convex()
    }
    fn bounds(&self) -> Aabb {
        self.0.bounds()
    }
    fn contains(&self, p: Vec3) -> bool {
        self.0.contains(p)
    }
    fn entry(&self, ray: &Ray) -> Option<BoxHit> {
        self.0.entry(ray)
    }
    fn exit(&self, ray: &Ray) -> BoxHit {
        self.0.exit(ray)
    }
    fn exit_distance(&self, ray: &Ray) -> f32 {
        self.0.exit_distance(ray)
    }
    fn flight_exit<'e>(&'e self, ray: &'e Ray) -> CountingExit<'e> {
        FLIGHTS.fetch_add(1, Ordering::Relaxed);
        CountingExit {
            exit: self.0.flight_exit(ray),
            counted: false,
        }
    }
}

struct Compare(RenderOptions, u32);

impl SceneVisitor for Compare {
    type Output = Result<(), volpt_render::RenderError>;
    fn visit<S: RenderScene>(self, scene: &S) -> Self::Output {
        let (vertices, triangles) = cuboid(scene.bounds());
        let buffers = build(&vertices, &triangles).expect("a box is a closed mesh");
        let res = resolution_for(buffers.bounds, self.1);
        let buffers = buffers.with_distances(res);
        let meshed = WithShape {
            scene,
            shape: BoundaryShape::Mesh(buffers.mesh()),
        };
        let (mut boxed_rate, mut mesh_rate) = (0.0, 0.0);
        for round in 0..3 {
            let (box_image, box_stats) = render(scene, &self.0, &|_, _| {})?;
            let (mesh_image, mesh_stats) = render(&meshed, &self.0, &|_, _| {})?;
            let same = box_image.pixels == mesh_image.pixels;
            println!(
                "round {round}: box {:.3e} segments/s, mesh {:.3e} segments/s ({:.3}x), {} segments \
                 each, images {}",
                box_stats.segments_per_second(),
                mesh_stats.segments_per_second(),
                mesh_stats.segments_per_second() / box_stats.segments_per_second(),
                box_stats.counters.segments,
                if same { "identical" } else { "DIFFER" }
            );
            boxed_rate += box_stats.segments_per_second();
            mesh_rate += mesh_stats.segments_per_second();
        }
        println!("mean ratio mesh/box: {:.3}", mesh_rate / boxed_rate);
        let counted = WithShape {
            scene,
            shape: Counting(BoundaryShape::Mesh(buffers.mesh())),
        };
        render(&counted, &self.0, &|_, _| {})?;
        let (flights, casts) = (
            FLIGHTS.load(Ordering::Relaxed),
            CASTS.load(Ordering::Relaxed),
        );
        println!(
            "distance grid {}x{}x{}: {casts} of {flights} free flights cast a ray ({:.3})",
            res[0],
            res[1],
            res[2],
            casts as f64 / flights.max(1) as f64
        );
        Ok(())
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let scene = PathBuf::from(
        args.next()
            .ok_or("usage: mesh_speed SCENE [SPP] [RESOLUTION] [DISTANCE_GRID_CELLS]")?,
    );
    let spp: u32 = args.next().map_or(Ok(4), |s| s.parse())?;
    let resolution: u32 = args.next().map_or(Ok(64), |s| s.parse())?;
    let cells: u32 = args.next().map_or(Ok(DISTANCE_RESOLUTION), |s| s.parse())?;
    let config = Config {
        spp: Some(spp),
        resolution: Some((resolution, resolution)),
        ..Config::default()
    };
    let desc = SceneAssembler::new(config).assemble(builder_for(&scene)?.as_ref())?;
    let options = RenderOptions {
        spp,
        seed: 0,
        threads: None,
    };
    with_scene(&desc, path_settings(&desc), Compare(options, cells))?;
    Ok(())
}
