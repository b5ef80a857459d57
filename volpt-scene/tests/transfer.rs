//! Transfer functions: the text format, evaluation and application to grids.

use std::path::{Path, PathBuf};

use volpt_scene::{Bounds, GridConvention, GridDesc, SceneError, TransferFunction};

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/transfer/bucky.txt")
}

fn parse(text: &str) -> Result<TransferFunction, SceneError> {
    TransferFunction::parse(text, Path::new("tf.txt"))
}

fn assert_near(a: [f32; 3], b: [f32; 3]) {
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < 1e-6, "{a:?} vs {b:?}");
    }
}

/// The error's line and field, after checking the message names the file and line.
fn invalid(text: &str) -> (usize, String) {
    match parse(text) {
        Err(err @ SceneError::InvalidValue { .. }) => {
            let message = err.to_string();
            let SceneError::InvalidValue { line, field, .. } = err else {
                unreachable!()
            };
            assert!(message.starts_with(&format!("tf.txt:{line}:")), "{message}");
            (line, field)
        }
        Err(other) => panic!("expected an invalid value, found {other}"),
        Ok(tf) => panic!("expected an error, parsed {tf:?}"),
    }
}

#[test]
fn fixture_parses_with_comments() {
    let tf = TransferFunction::read(&fixture()).unwrap();
    assert_eq!(tf.points().len(), 3);
    assert_eq!(tf.points()[1].density, 20.0);
    assert_eq!(tf.points()[1].albedo, [0.8, 0.6, 0.4]);
}

#[test]
fn eval_is_piecewise_linear_and_clamped() {
    let tf = TransferFunction::read(&fixture()).unwrap();
    assert_near(tf.eval(-5.0), [0.9, 0.2, 0.1]);
    assert_near(tf.eval(0.0), [0.9, 0.2, 0.1]);
    assert_near(tf.eval(10.0), [0.85, 0.4, 0.25]);
    assert_near(tf.eval(20.0), [0.8, 0.6, 0.4]);
    assert_near(tf.eval(30.0), [0.9, 0.8, 0.7]);
    assert_near(tf.eval(40.0), [1.0; 3]);
    assert_near(tf.eval(1e9), [1.0; 3]);
    assert_near(tf.eval(f32::INFINITY), [1.0; 3]);
    assert_near(tf.eval(f32::NAN), [0.9, 0.2, 0.1]);
}

#[test]
fn one_point_is_a_constant() {
    let tf = parse("5 0.5 0.25 1\n").unwrap();
    for d in [0.0, 5.0, 100.0] {
        assert_eq!(tf.eval(d), [0.5, 0.25, 1.0]);
    }
}

#[test]
fn apply_makes_an_rgb_grid_of_the_same_shape() {
    let tf = TransferFunction::read(&fixture()).unwrap();
    let density = GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution: [3, 1, 1],
        channels: 1,
        bounds: Bounds {
            min: [0.0; 3],
            max: [3.0, 1.0, 1.0],
        },
        convention: GridConvention::Vertex,
        data: vec![0.0, 20.0, 40.0],
    };
    let albedo = tf.apply(&density);
    assert_eq!(albedo.channels, 3);
    assert_eq!(albedo.resolution, density.resolution);
    assert_eq!(albedo.bounds, density.bounds);
    assert_eq!(albedo.convention, density.convention);
    assert_eq!(albedo.data.len(), 9);
    assert_near(albedo.data[3..6].try_into().unwrap(), [0.8, 0.6, 0.4]);
    assert!(albedo.data.iter().all(|v| (0.0..=1.0).contains(v)));
}

#[test]
fn densities_must_increase_strictly() {
    assert_eq!(
        invalid("0 1 1 1\n1 1 1 1\n1 1 1 1\n"),
        (3, "density".into())
    );
    assert_eq!(invalid("# c\n2 1 1 1\n\n1 1 1 1\n"), (4, "density".into()));
}

#[test]
fn albedo_components_must_be_in_the_unit_interval() {
    assert_eq!(invalid("0 1 1.5 1\n"), (1, "albedo green".into()));
    assert_eq!(invalid("0 -0.1 1 1\n"), (1, "albedo red".into()));
    assert_eq!(invalid("0 1 1 nan\n"), (1, "albedo blue".into()));
}

#[test]
fn malformed_lines() {
    assert_eq!(invalid("0 1 1\n"), (1, "control point".into()));
    assert_eq!(invalid("0 1 1 1 1\n"), (1, "control point".into()));
    assert_eq!(invalid("zero 1 1 1\n"), (1, "density".into()));
    assert_eq!(invalid("inf 1 1 1\n"), (1, "density".into()));
}

#[test]
fn an_empty_file_is_an_error() {
    let err = parse("# nothing here\n\n").unwrap_err();
    assert!(matches!(err, SceneError::Missing { .. }), "{err}");
    assert!(err.to_string().contains("tf.txt"), "{err}");
}

#[test]
fn a_missing_file_is_named() {
    let err = TransferFunction::read(Path::new("/nonexistent/tf.txt")).unwrap_err();
    assert!(matches!(err, SceneError::Io { .. }));
    assert!(err.to_string().contains("/nonexistent/tf.txt"), "{err}");
}
