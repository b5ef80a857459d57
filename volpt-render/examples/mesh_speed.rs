//! A scene's box boundary against the same box as a 12-triangle mesh (each as the factory holds
//! it, a [`BoundaryShape`]), on the CPU, same run:
//! segments per second of each (alternating, three rounds) and whether the images agree bit for
//! bit (the mesh of a box traces the box's paths).
//!
//!     cargo run --release -p volpt-render --example mesh_speed -- scenes/homogeneous-cube/scene.xml 4 64

use std::path::PathBuf;

use volpt_core::mesh::build::build;
use volpt_core::mesh::primitives::cuboid;
use volpt_core::{BoundaryShape, WithShape};
use volpt_render::{path_settings, render, with_scene, RenderOptions, RenderScene, SceneVisitor};
use volpt_scene::{builder_for, Config, SceneAssembler};

struct Compare(RenderOptions);

impl SceneVisitor for Compare {
    type Output = Result<(), volpt_render::RenderError>;
    fn visit<S: RenderScene>(self, scene: &S) -> Self::Output {
        let (vertices, triangles) = cuboid(scene.bounds());
        let buffers = build(&vertices, &triangles).expect("a box is a closed mesh");
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
        Ok(())
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let scene = PathBuf::from(
        args.next()
            .ok_or("usage: mesh_speed SCENE [SPP] [RESOLUTION]")?,
    );
    let spp: u32 = args.next().map_or(Ok(4), |s| s.parse())?;
    let resolution: u32 = args.next().map_or(Ok(64), |s| s.parse())?;
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
    with_scene(&desc, path_settings(&desc), Compare(options))?;
    Ok(())
}
