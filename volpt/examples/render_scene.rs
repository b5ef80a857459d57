//! Renders a scene through the library, as `volpt render SCENE -o OUT.exr` does on the CPU.
//!
//!     cargo run --release -p volpt --example render_scene -- scenes/example/cube.xml cube.exr

use volpt::{Backend, BackendOptions, RenderSettings, Scene};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (Some(scene_file), Some(output)) = (args.next(), args.next()) else {
        return Err("usage: render_scene SCENE OUTPUT.exr".into());
    };
    let settings = RenderSettings {
        spp: Some(16),
        ..RenderSettings::default()
    };
    let scene = Scene::load(&scene_file, &settings)?;
    let backend = Backend::open(&BackendOptions::default())?;
    let mut film = scene.film();
    let rendered = backend.render(&scene, &mut film, 0..scene.spp(), &volpt::Quiet)?;
    film.image(scene.spp()).write_exr(output.as_ref())?;
    println!(
        "{} in {:.2} s",
        scene.variant(),
        rendered.stats.elapsed.as_secs_f64()
    );
    Ok(())
}
