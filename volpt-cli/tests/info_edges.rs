//! `volpt info` says which specialisation rules fired, on both sides of their edges: from a scene
//! that no rule simplifies, one value set exactly to a rule's condition (g = 0, a constant grid, an
//! IOR ratio of 1) lists that rule, and set just beside it (g = 0.01, one sample different, an IOR
//! ratio of 1.001) lists none. Which rule
//! fires where is tested case by case in `tests/tests/effects.rs`; this checks that what the
//! factory decides is what the user is told, through the scene files the CLI reads.

use std::path::Path;
use std::process::Command;

use volpt::scene_files::description::*;
use volpt::scene_files::mitsuba::{write_mitsuba3, NO_ROULETTE_DEPTH};
use volpt::scene_files::Simplification;

/// A unit cube of 3x2x4 density samples of 2 (the last one `last`), a 2x2x2 albedo grid of
/// (0.9, 0.7, 0.8) (green of the last sample `last_green`), Henyey-Greenstein `g`, a smooth
/// dielectric of IOR `int_ior` / 1.2, no depth limit and no roulette.
fn scene(g: f32, last: f32, last_green: f32, int_ior: f32) -> SceneDescription {
    let bounds = Bounds {
        min: [-0.5; 3],
        max: [0.5; 3],
    };
    let grid = |resolution: [u32; 3], sample: &[f32], last: &[f32]| {
        let n = resolution.iter().product::<u32>() as usize;
        let mut data: Vec<f32> = sample
            .iter()
            .copied()
            .cycle()
            .take(n * sample.len())
            .collect();
        let at = data.len() - last.len();
        data[at..].copy_from_slice(last);
        GridDesc {
            layout: volpt::scene_files::SampleLayout::Dense,
            resolution,
            channels: sample.len() as u32,
            bounds,
            convention: GridConvention::Cell,
            data,
        }
    };
    SceneDescription {
        lights: Default::default(),
        camera: CameraDesc {
            to_world: [
                [-1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, -1.0, 3.0],
                [0.0, 0.0, 0.0, 1.0],
            ],
            fov_degrees: 30.0,
            fov_axis: FovAxis::X,
            projection: Projection::Perspective,
        },
        film: FilmDesc {
            width: 8,
            height: 8,
        },
        spp: 4,
        integrator: IntegratorDesc {
            max_depth: None,
            rr_depth: None,
        },
        boundary: BoundaryDesc {
            bounds,
            bsdf: BsdfDesc::Dielectric {
                int_ior,
                ext_ior: 1.2,
            },
            mesh: None,
        },
        medium: MediumDesc {
            density: DensityDesc::Grid(grid([3, 2, 4], &[2.0], &[last])),
            scale: 1.0,
            albedo: AlbedoDesc::Grid(grid([2, 2, 2], &[0.9, 0.7, 0.8], &[0.9, last_green, 0.8])),
            phase: PhaseDesc::HenyeyGreenstein { g },
            lookup: Default::default(),
            storage: Default::default(),
        },
        environment: EnvironmentDesc::Constant([1.0; 3]),
    }
}

/// The `specialised:` lines of `volpt info` on `desc`, written as a Mitsuba 3 scene. The exporter
/// spells "no roulette" as a huge `rr_depth` (Mitsuba 3 has no -1 for it), which is a depth limit
/// to the factory; the scene says -1 instead, which volpt reads as no roulette.
fn rules_reported(dir: &Path, name: &str, desc: &SceneDescription) -> Vec<String> {
    let xml = write_mitsuba3(desc, dir, name).expect("export")[0].clone();
    let text = std::fs::read_to_string(&xml).expect("read scene");
    let huge = format!("name=\"rr_depth\" value=\"{NO_ROULETTE_DEPTH}\"");
    assert!(
        text.contains(&huge),
        "{name}: no rr_depth {NO_ROULETTE_DEPTH}"
    );
    std::fs::write(&xml, text.replace(&huge, "name=\"rr_depth\" value=\"-1\"")).expect("write");
    let out = Command::new(env!("CARGO_BIN_EXE_volpt"))
        .arg("info")
        .arg(&xml)
        .env("RUST_LOG", "error")
        .output()
        .expect("run volpt");
    assert!(
        out.status.success(),
        "volpt info {name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .expect("UTF-8")
        .lines()
        .filter_map(|l| l.trim().strip_prefix("specialised: ").map(str::to_owned))
        .collect()
}

/// The general values of each axis, none of which a rule simplifies.
const G: f32 = 0.3;
const LAST: f32 = 3.0;
const LAST_GREEN: f32 = 0.5;
const IOR: f32 = 1.5;

#[test]
fn info_reports_each_rule_at_its_edge_and_none_just_beside_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let general = rules_reported(dir.path(), "general", &scene(G, LAST, LAST_GREEN, IOR));
    assert_eq!(
        general,
        Vec::<String>::new(),
        "general values: no rule fires"
    );
    for (rule, exact, beside) in [
        (
            Simplification::ZeroAsymmetry,
            scene(0.0, LAST, LAST_GREEN, IOR),
            vec![
                ("g = 0.01", scene(0.01, LAST, LAST_GREEN, IOR)),
                ("g = -0.01", scene(-0.01, LAST, LAST_GREEN, IOR)),
            ],
        ),
        (
            Simplification::ConstantDensityGrid,
            scene(G, 2.0, LAST_GREEN, IOR),
            vec![(
                "one density sample 0.1% higher",
                scene(G, 2.002, LAST_GREEN, IOR),
            )],
        ),
        (
            Simplification::ConstantAlbedoGrid,
            scene(G, LAST, 0.7, IOR),
            vec![(
                "one albedo sample's green 0.1% higher",
                scene(G, LAST, 0.7007, IOR),
            )],
        ),
        (
            Simplification::UnitIorRatio,
            scene(G, LAST, LAST_GREEN, 1.2),
            vec![("IOR ratio 1.001", scene(G, LAST, LAST_GREEN, 1.2012))],
        ),
    ] {
        let name = format!("{rule:?}");
        let reported = rules_reported(dir.path(), &name, &exact);
        assert_eq!(reported, [rule.to_string()], "{name}: exactly at the edge");
        for (k, (what, desc)) in beside.iter().enumerate() {
            let reported = rules_reported(dir.path(), &format!("{name}-beside-{k}"), desc);
            assert_eq!(
                reported,
                Vec::<String>::new(),
                "{name}, {what}: beside the edge no rule may fire"
            );
        }
    }
}
