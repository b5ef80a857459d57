//! The backend of a caller who names none (`volpt print compensate` without `--backend`,
//! `volpt.compensate_print(backend=None)`): the rule on every probe, and the real choice on this
//! machine (the CPU where no GPU is usable, saying why).

use volpt::{preferred_kind, Backend, BackendKind, GpuOptions, GpuProbe, Gpus, StrategyChoice};

#[test]
fn the_gpu_is_preferred_exactly_where_the_probe_finds_one_or_gpu_options_are_given() {
    let none = GpuOptions::default();
    let cases = [
        (
            GpuProbe::NoKernels,
            BackendKind::Cpu,
            "carries no GPU kernels",
        ),
        (
            GpuProbe::NoDriver("no CUDA driver".into()),
            BackendKind::Cpu,
            "no GPU is usable (no CUDA driver)",
        ),
        (GpuProbe::Gpus(0), BackendKind::Cpu, "sees no GPU"),
        (
            GpuProbe::Gpus(1),
            BackendKind::Cuda,
            "a GPU is present (1 seen",
        ),
        (GpuProbe::Gpus(8), BackendKind::Cuda, "(8 seen"),
    ];
    for (probe, kind, why) in cases {
        let (chosen, reason) = preferred_kind(&probe, &none);
        assert_eq!(chosen, kind, "{probe:?}");
        assert!(reason.contains(why), "{probe:?}: {reason}");
    }
    // A GPU option asks for the GPU whatever the probe says (its failure to open is then an
    // error, as with --backend cuda).
    for gpu in [
        GpuOptions {
            gpus: Gpus::All,
            ..none
        },
        GpuOptions {
            strategy: Some(StrategyChoice::Auto),
            ..none
        },
        GpuOptions {
            bricked: true,
            ..none
        },
    ] {
        for probe in [GpuProbe::NoKernels, GpuProbe::Gpus(0)] {
            let (chosen, reason) = preferred_kind(&probe, &gpu);
            assert_eq!(chosen, BackendKind::Cuda, "{gpu:?} {probe:?}");
            assert!(reason.contains("GPU options"), "{reason}");
        }
    }
}

#[test]
fn this_machine_s_choice_follows_its_probe_and_says_why() {
    let probe = GpuProbe::now();
    let preferred = Backend::open_preferred(&GpuOptions::default()).unwrap();
    match probe {
        GpuProbe::Gpus(n) if n > 0 => {
            // A GPU machine: the GPU, unless it did not open (said so).
            if preferred.backend.kind() == BackendKind::Cpu {
                assert!(
                    preferred.reason.contains("did not open"),
                    "{}",
                    preferred.reason
                );
            }
        }
        _ => {
            assert_eq!(preferred.backend.kind(), BackendKind::Cpu, "{probe:?}");
            assert_eq!(
                preferred.reason,
                preferred_kind(&probe, &GpuOptions::default()).1
            );
        }
    }
}

#[test]
fn a_gpu_the_probe_found_that_does_not_open_falls_back_to_the_cpu_unless_gpu_options_were_given() {
    if matches!(GpuProbe::now(), GpuProbe::Gpus(n) if n > 0) {
        return; // Here the GPU would open: the fallback needs a machine where it does not.
    }
    // A probe that claims a GPU where none opens (as a GPU whose driver fails at start-up).
    let claimed = GpuProbe::Gpus(1);
    let preferred = Backend::open_preferred_with(&claimed, &GpuOptions::default()).unwrap();
    assert_eq!(preferred.backend.kind(), BackendKind::Cpu);
    assert!(
        preferred.reason.starts_with("the GPU did not open ("),
        "{}",
        preferred.reason
    );
    // Asked for by its options, the GPU's failure is the caller's error.
    let asked = GpuOptions {
        gpus: Gpus::All,
        ..GpuOptions::default()
    };
    assert!(Backend::open_preferred_with(&claimed, &asked).is_err());
}
