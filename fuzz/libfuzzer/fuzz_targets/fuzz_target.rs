//! One libFuzzer binary for every target, picked by `VOLPT_FUZZ_TARGET` (one build, a run per target).

#![no_main]

use std::sync::OnceLock;

use volpt_fuzz::Target;

fn target() -> Target {
    static TARGET: OnceLock<Target> = OnceLock::new();
    *TARGET.get_or_init(|| {
        let name = std::env::var("VOLPT_FUZZ_TARGET").unwrap_or_default();
        Target::ALL
            .into_iter()
            .find(|t| t.name() == name)
            .unwrap_or_else(|| {
                let names: Vec<_> = Target::ALL.iter().map(|t| t.name()).collect();
                panic!("VOLPT_FUZZ_TARGET={name:?}: expected one of {names:?}")
            })
    })
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| target().run(data));
