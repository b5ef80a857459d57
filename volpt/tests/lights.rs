//! The lights through the whole stack (Mitsuba and TOML loaders, factory, CPU backend, facade):
//! `scenes/lights/sun-slab.xml` against its closed-form single-scattering radiance (the loader's
//! direction and irradiance conventions included), `volpt info`'s words and its warning behind a
//! dielectric, the lights' parameters between renders, and the Mitsuba 3 export read back.

mod common;

use std::path::{Path, PathBuf};

use volpt::{ParamValue, RenderSettings, Scene};

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/lights")
}

fn settings(params: &[(&str, &str)]) -> RenderSettings {
    RenderSettings {
        seed: 7,
        params: params
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
        ..RenderSettings::default()
    }
}

fn hg(g: f64, cos: f64) -> f64 {
    (1.0 - g * g) / (4.0 * std::f64::consts::PI * (1.0 + g * g - 2.0 * g * cos).powf(1.5))
}

/// What `sun-slab.xml` says every pixel sees: the single-scattering integral along a vertical ray
/// through the slab `[0, d]` lit by a sun `zenith` from the zenith (closed form over the depth).
fn sun_slab_radiance() -> f64 {
    let (sigma_t, albedo, g, d, irradiance) = (1.5f64, 0.8f64, 0.4f64, 1.0f64, 2.0f64);
    let mu = 40f64.to_radians().cos();
    let k = sigma_t * (1.0 - 1.0 / mu);
    sigma_t * albedo * hg(g, mu) * irradiance * (-sigma_t * d / mu).exp() * (1.0 - (-k * d).exp())
        / k
}

#[test]
fn a_directional_light_over_a_slab_renders_the_single_scattering_radiance() {
    let scene = Scene::load(scenes().join("sun-slab.xml"), &settings(&[("spp", "256")])).unwrap();
    let film = common::render(&scene);
    // Every pixel is an independent mean of `spp` paths of the same radiance (orthographic rays
    // through a slab wider than any light path here).
    let values: Vec<f64> = film
        .sums
        .iter()
        .map(|s| s[0] / f64::from(scene.spp()))
        .collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let (se, expected) = ((var / n).sqrt(), sun_slab_radiance());
    assert!(
        (mean - expected).abs() <= 5.0 * se && (mean - expected).abs() <= 0.02 * expected,
        "mean {mean} +- {se}, expected {expected}"
    );
    let info = scene.info();
    let lights = info.get("lights").unwrap();
    assert!(lights.contains("delta direction"), "{lights}");
    assert!(lights.contains("next-event estimation"), "{lights}");
}

#[test]
fn volpt_info_warns_that_a_delta_light_adds_nothing_behind_a_dielectric() {
    let scene = Scene::load(
        scenes().join("sun-slab.xml"),
        &settings(&[("boundary", "dielectric")]),
    )
    .unwrap();
    let info = scene.info();
    let lights = info.get("lights").unwrap();
    assert!(
        lights.contains("WARNING") && lights.contains("smooth dielectric"),
        "{lights}"
    );
    // And indeed: no path reaches the sun, the image is black.
    let film = common::render(&scene);
    assert!(film.sums.iter().all(|s| *s == [0.0; 3]));
}

#[test]
fn the_lights_parameters_change_the_render_and_a_refused_value_changes_nothing() {
    let mut scene = Scene::load(scenes().join("sun-slab.xml"), &settings(&[("spp", "4")])).unwrap();
    let keys: Vec<String> = scene.params().into_iter().map(|(k, _)| k).collect();
    for key in ["sun.direction", "sun.irradiance", "sun.angular_radius"] {
        assert!(keys.iter().any(|k| k == key), "{key} in {keys:?}");
    }
    assert!(!keys.iter().any(|k| k.starts_with("light.")), "{keys:?}");
    assert_eq!(
        scene.get("sun.irradiance").unwrap(),
        ParamValue::Rgb([2.0; 3])
    );
    let before = common::render(&scene);
    // Twice the irradiance: every sum exactly twice (a power of two scales without rounding).
    scene
        .set("sun.irradiance", ParamValue::Rgb([4.0; 3]))
        .unwrap();
    let doubled = common::render(&scene);
    for (a, b) in before.sums.iter().zip(&doubled.sums) {
        assert_eq!([a[0] * 2.0, a[1] * 2.0, a[2] * 2.0], *b);
    }
    let fingerprint = scene.fingerprint();
    assert!(scene
        .set("sun.irradiance", ParamValue::Rgb([-1.0, 0.0, 0.0]))
        .is_err());
    assert!(scene
        .set("sun.direction", ParamValue::Vec3([0.0; 3]))
        .is_err());
    assert!(scene
        .set("light.intensity", ParamValue::Rgb([1.0; 3]))
        .is_err());
    assert_eq!(
        scene.fingerprint(),
        fingerprint,
        "a refusal changes nothing"
    );
    assert_eq!(
        scene.get("sun.irradiance").unwrap(),
        ParamValue::Rgb([4.0; 3])
    );
    // The sun from below lights the slab otherwise.
    scene
        .set("sun.direction", ParamValue::Vec3([0.64, 0.0, 0.77]))
        .unwrap();
    let below = common::render(&scene);
    let total = |f: &volpt::Film| f.sums.iter().map(|s| s[0]).sum::<f64>();
    assert!(total(&below) > 0.0 && total(&below) != total(&doubled));
}

#[test]
fn lights_in_a_toml_scene_and_mitsuba_3_export_read_back_the_same() {
    let toml = Scene::load(scenes().join("lights.toml"), &settings(&[])).unwrap();
    let lights = toml.description().lights;
    let sun = lights.sun.unwrap();
    assert_eq!(sun.angular_radius, 5.0);
    let spot = lights.spot.unwrap();
    assert_eq!(spot.cone.unwrap().direction, [0.2, -1.6, 0.0]);
    assert_eq!(spot.cone.unwrap().beam_width, 20.0);

    let spot_fog = Scene::load(scenes().join("spot-fog.xml"), &settings(&[])).unwrap();
    let dir = std::env::temp_dir().join(format!("volpt-lights-export-{}", std::process::id()));
    let written =
        volpt_scene::mitsuba::write_mitsuba3(spot_fog.description(), &dir, "spot-fog").unwrap();
    let back = Scene::load(&written[0], &settings(&[])).unwrap();
    let (a, b) = (spot_fog.description().lights, back.description().lights);
    let (sa, sb) = (a.spot.unwrap(), b.spot.unwrap());
    assert_eq!(sa.position, sb.position);
    assert_eq!(sa.intensity, sb.intensity);
    let (ca, cb) = (sa.cone.unwrap(), sb.cone.unwrap());
    let unit = |d: [f32; 3]| {
        let l = d.iter().map(|c| c * c).sum::<f32>().sqrt();
        d.map(|c| c / l)
    };
    for (x, y) in unit(ca.direction).iter().zip(unit(cb.direction)) {
        assert!((x - y).abs() < 1e-5, "{ca:?} {cb:?}");
    }
    assert_eq!(
        (ca.cutoff_angle, ca.beam_width),
        (cb.cutoff_angle, cb.beam_width)
    );
    // A sun with an angular radius has no Mitsuba 3 spelling.
    let error = volpt_scene::mitsuba::write_mitsuba3(toml.description(), &dir, "lights")
        .unwrap_err()
        .to_string();
    assert!(error.contains("angular radius"), "{error}");
    std::fs::remove_dir_all(&dir).ok();
}
