//! The names of the library's choices ([`volpt::names`]) and its bounds: every name parses back to
//! its value and is unique among its choice's; a name no value has is refused with the setting's
//! key and the names it takes; the majorant grid's bound is refused by the library, once, with the
//! setting's key (which the front ends spell their own way: volpt-cli/tests/cli.rs,
//! python/tests/test_errors.py).

use std::collections::HashSet;

use volpt::names::{expected, names, parse};
use volpt::{
    Accumulation, BackendKind, Effects, Error, Estimator, GridLookup, Math, Named, RenderSettings,
    Roulette, Scene, Strategy, StrategyChoice, Tracking, VolumeMemory, MAJORANT_RESOLUTION,
};

/// Every value of `T` round-trips through its name; the names are unique and non-empty, and
/// each value says what it does; a name of no value is refused naming the setting.
fn round_trips<T: Named>() {
    let mut seen = HashSet::new();
    for &value in T::all() {
        let name = value.name();
        assert!(!name.is_empty() && !value.about().is_empty(), "{value:?}");
        assert!(seen.insert(name), "{name} twice among {}", T::KEY);
        assert_eq!(parse::<T>(name).unwrap(), value, "{name}");
    }
    assert_eq!(names::<T>().len(), T::all().len());
    match parse::<T>("no-such-name").unwrap_err() {
        Error::Setting {
            key,
            expected: e,
            found,
        } => {
            assert_eq!(key, T::KEY);
            assert_eq!(e, expected::<T>());
            assert_eq!(found, "\"no-such-name\"");
        }
        error => panic!("{}: {error:?}", T::KEY),
    }
}

#[test]
fn every_choice_names_round_trip() {
    round_trips::<BackendKind>();
    round_trips::<StrategyChoice>();
    round_trips::<Strategy>();
    round_trips::<Math>();
    round_trips::<GridLookup>();
    round_trips::<Estimator>();
    round_trips::<Roulette>();
    round_trips::<Tracking>();
    round_trips::<Effects>();
    round_trips::<Accumulation>();
    round_trips::<VolumeMemory>();
}

#[test]
fn the_tables_name_every_value_as_the_crates_below_do() {
    // Where a crate below names its values itself, the table agrees with it.
    for &m in Math::ALL {
        assert_eq!(Named::name(m), m.name());
    }
    for m in VolumeMemory::ALL {
        assert_eq!(Named::name(m), m.name());
        assert_eq!(m.name().parse::<VolumeMemory>().unwrap(), m);
    }
    assert_eq!(StrategyChoice::all().len(), Strategy::ALL.len() + 1);
    for &choice in StrategyChoice::all() {
        assert_eq!(Named::name(choice), choice.to_string());
    }
    // The facade's own choices display and parse by the table.
    for &kind in BackendKind::all() {
        assert_eq!(kind.to_string().parse::<BackendKind>().unwrap(), kind);
    }
    for &tracking in Tracking::all() {
        assert_eq!(tracking.to_string().parse::<Tracking>().unwrap(), tracking);
    }
    assert_eq!(
        "auto".parse::<StrategyChoice>().unwrap(),
        StrategyChoice::Auto
    );
    assert_eq!(
        parse::<GridLookup>("texture-f16").unwrap(),
        GridLookup::TextureHalf
    );
}

#[test]
fn the_majorant_grid_bound_is_the_librarys() {
    let cube = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml");
    let load = |cells: u32| {
        let settings = RenderSettings {
            majorant_resolution: Some(cells),
            resolution: Some((4, 4)),
            ..RenderSettings::default()
        };
        Scene::load(&cube, &settings)
    };
    for cells in [*MAJORANT_RESOLUTION.start(), *MAJORANT_RESOLUTION.end()] {
        assert_eq!(
            load(cells).unwrap().path_settings().majorant_resolution,
            cells
        );
    }
    for cells in [0, MAJORANT_RESOLUTION.end() + 1, u32::MAX] {
        let error = load(cells).unwrap_err();
        assert!(
            matches!(&error, Error::Setting { key: "majorant_resolution", expected, found }
                if expected == "1 to 1024 cells" && *found == cells.to_string()),
            "{error:?}"
        );
        assert_eq!(
            error.to_string(),
            format!("majorant_resolution: expected 1 to 1024 cells, found {cells}")
        );
    }
}

#[test]
fn the_gpu_knobs_bounds_are_refused_before_any_gpu_is_opened() {
    use volpt::{Backend, BackendOptions, GpuOptions, MAX_REGISTERS, REFILL_AT, TILES};
    let refused = |gpu: GpuOptions, key: &str, expected: &str, found: &str| {
        for options in [
            BackendOptions::cuda(gpu),
            BackendOptions {
                gpu,
                ..Default::default()
            },
        ] {
            match Backend::open(&options) {
                Err(Error::Setting {
                    key: k,
                    expected: e,
                    found: f,
                }) => {
                    assert_eq!((k, e.as_str(), f.as_str()), (key, expected, found))
                }
                Err(error) => panic!("{error:?}"),
                Ok(_) => panic!("{gpu:?} opened"),
            }
        }
    };
    let registers = |n| GpuOptions {
        max_registers: Some(n),
        ..GpuOptions::default()
    };
    let refill = |n| GpuOptions {
        refill_at: Some(n),
        ..GpuOptions::default()
    };
    refused(
        registers(MAX_REGISTERS.start() - 1),
        "max_registers",
        "16 to 255",
        "15",
    );
    refused(
        registers(MAX_REGISTERS.end() + 1),
        "max_registers",
        "16 to 255",
        "256",
    );
    refused(refill(REFILL_AT.start() - 1), "refill_at", "1 to 32", "0");
    refused(refill(REFILL_AT.end() + 1), "refill_at", "1 to 32", "33");
    let tiles = |t| GpuOptions {
        tiles: Some(t),
        ..GpuOptions::default()
    };
    let each = "columns and rows of 1 to 4096 each";
    refused(tiles([TILES.start() - 1, 3]), "tiles", each, "0,3");
    refused(tiles([4, TILES.end() + 1]), "tiles", each, "4,4097");
    // In bounds, the CPU refuses them for what they are: GPU knobs.
    let in_bounds = Backend::open(&BackendOptions {
        gpu: registers(*MAX_REGISTERS.end()),
        ..Default::default()
    })
    .err();
    assert!(
        matches!(
            &in_bounds,
            Some(Error::Conflict { key: "max_registers", value, with: "backend", with_value, .. })
                if value == "255" && with_value == "cpu"
        ),
        "{in_bounds:?}"
    );
}

#[test]
fn an_unknown_parameter_is_its_own_error() {
    let cube = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml");
    let mut scene = Scene::load(cube, &RenderSettings::default()).unwrap();
    for error in [
        scene.get("medium.density").unwrap_err(),
        scene
            .set("medium.density", volpt::ParamValue::Float(1.0))
            .unwrap_err(),
    ] {
        assert!(
            matches!(&error, Error::UnknownParam { key, expected }
                if key == "medium.density" && expected.starts_with("one of spp, seed")),
            "{error:?}"
        );
    }
    assert!(matches!(
        scene.set("spp", volpt::ParamValue::Int(0)).unwrap_err(),
        Error::Param { .. }
    ));
}

/// Settings that cannot go together are one typed error naming both keys and values in the
/// library's spelling, with a reason that names no key: each front end spells the keys its own
/// way ([`Error::spelled`]).
#[test]
fn conflicts_between_settings_are_typed_with_both_keys() {
    use volpt::{Backend, BackendOptions, GpuOptions};
    let conflict = |error: Error| match error {
        Error::Conflict {
            key,
            value,
            with,
            with_value,
            why,
            ..
        } => {
            // Keys of several words are unmistakable in a sentence; one-word keys are words.
            for k in [
                "refill_at",
                "max_registers",
                "majorant_resolution",
                "volume_memory",
            ] {
                assert!(!why.contains(k), "the reason names {k}: {why}");
            }
            (key, value, with, with_value)
        }
        other => panic!("not a conflict: {other:?}"),
    };
    let open = |kind, gpu| {
        Backend::open(&BackendOptions { kind, gpu })
            .err()
            .expect("refused")
    };
    let gpu = |f: fn(&mut GpuOptions)| {
        let mut gpu = GpuOptions::default();
        f(&mut gpu);
        gpu
    };
    let strategy = gpu(|g| g.strategy = Some(StrategyChoice::Fixed(Strategy::NaiveSk)));
    assert_eq!(
        conflict(open(BackendKind::Cpu, strategy)),
        ("strategy", "naive-sk".into(), "backend", "cpu".into())
    );
    // Refused before the driver is asked for a GPU.
    let tiles = gpu(|g| {
        g.strategy = Some(StrategyChoice::Auto);
        g.tiles = Some([2, 2]);
    });
    assert_eq!(
        conflict(open(BackendKind::Cuda, tiles)),
        ("tiles", "2,2".into(), "strategy", "auto".into())
    );
    let refill = gpu(|g| {
        g.strategy = Some(StrategyChoice::Fixed(Strategy::NaiveSk));
        g.refill_at = Some(8);
    });
    assert_eq!(
        conflict(open(BackendKind::Cuda, refill)),
        ("refill_at", "8".into(), "strategy", "naive-sk".into())
    );
    let cube = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml");
    let settings = RenderSettings {
        tracking: Some(Tracking::Global),
        majorant_resolution: Some(8),
        ..RenderSettings::default()
    };
    let error = Scene::load(&cube, &settings).expect_err("refused");
    let flags = error.spelled(&|key, value| {
        let flag = format!("--{}", key.replace('_', "-"));
        value.map_or(flag.clone(), |v| format!("{flag} {v}"))
    });
    assert_eq!(
        conflict(error),
        (
            "majorant_resolution",
            "8".into(),
            "tracking",
            "global".into()
        )
    );
    assert!(
        flags.starts_with("--majorant-resolution 8 with --tracking global: global tracking"),
        "{flags}"
    );
    // The same choices as a request's path settings over a loaded scene's: the same refusal.
    let scene = Scene::load(&cube, &RenderSettings::default()).unwrap();
    let error = settings.path_over(scene.path_settings()).unwrap_err();
    assert_eq!(
        conflict(error),
        (
            "majorant_resolution",
            "8".into(),
            "tracking",
            "global".into()
        )
    );
}
