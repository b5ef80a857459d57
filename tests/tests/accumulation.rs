//! The film's precision (`Accumulation`, `volpt converge --setting accumulation=f64,f32`): an f32
//! film is exactly the sequential f32 sum of the samples' radiance, an f64 film the f64 sum, and
//! both see the very same samples.

use volpt_render::{
    render_samples, with_scene, Accumulation, Film, RenderOptions, RenderScene, SceneVisitor,
};
use volpt_scene::description::{BsdfDesc, PhaseDesc};
use volpt_tests::{cube_scene, homogeneous};

const SPP: u32 = 48;

/// Films of `SPP` samples in each precision, and the radiance of every sample alone.
struct Films;

impl SceneVisitor for Films {
    type Output = (Film, Film, Vec<Film>);

    fn visit<S: RenderScene>(self, scene: &S) -> Self::Output {
        let (w, h) = (scene.camera().width, scene.camera().height);
        let options = RenderOptions {
            spp: SPP,
            seed: 5,
            threads: None,
        };
        let film = |accumulation, samples| {
            let mut film = Film::new(w, h).with_accumulation(accumulation);
            render_samples(scene, &mut film, samples, &options, &|_, _| {}).expect("render");
            film
        };
        let singles = (0..SPP)
            .map(|k| film(Accumulation::F64, k..k + 1))
            .collect();
        (
            film(Accumulation::F64, 0..SPP),
            film(Accumulation::F32, 0..SPP),
            singles,
        )
    }
}

#[test]
fn f32_film_is_the_sequential_f32_sum_of_the_samples() {
    let medium = homogeneous(2.0, 0.8, PhaseDesc::HenyeyGreenstein { g: 0.5 });
    let desc = cube_scene(6, 5, medium, BsdfDesc::Null, 1.3);
    let (f64_film, f32_film, singles) =
        with_scene(&desc, volpt_render::path_settings(&desc), Films);
    let mut rounded_somewhere = false;
    for (p, (&sum64, &sum32)) in f64_film.sums.iter().zip(&f32_film.sums).enumerate() {
        for c in 0..3 {
            let samples = singles.iter().map(|film| film.sums[p][c]);
            let (mut exact, mut single) = (0.0f64, 0.0f32);
            for r in samples {
                assert_eq!(r, r as f32 as f64, "one sample's sum is its f32 radiance");
                exact += r;
                single += r as f32;
            }
            assert_eq!(sum64[c], exact, "pixel {p} channel {c}: the f64 film");
            assert_eq!(
                sum32[c], single as f64,
                "pixel {p} channel {c}: the f32 film"
            );
            rounded_somewhere |= sum32[c] != sum64[c];
        }
    }
    assert!(
        rounded_somewhere,
        "the f32 film never rounded: the test proves nothing"
    );
}
