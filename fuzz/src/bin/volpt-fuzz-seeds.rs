//! `volpt-fuzz-seeds TARGET DIR`: writes the target's seed inputs into DIR (for `fuzz/run`).

use std::path::PathBuf;

use volpt_fuzz::{seeds, Target};

fn main() {
    let mut args = std::env::args().skip(1);
    let (Some(name), Some(dir)) = (args.next(), args.next().map(PathBuf::from)) else {
        eprintln!("usage: volpt-fuzz-seeds TARGET DIR");
        std::process::exit(2);
    };
    let Some(target) = Target::ALL.into_iter().find(|t| t.name() == name) else {
        let names: Vec<_> = Target::ALL.iter().map(|t| t.name()).collect();
        eprintln!("unknown target {name:?}: expected one of {names:?}");
        std::process::exit(2);
    };
    std::fs::create_dir_all(&dir).expect("create the corpus directory");
    for (i, seed) in seeds(target).iter().enumerate() {
        std::fs::write(dir.join(format!("seed-{i}")), seed).expect("write a seed");
    }
}
