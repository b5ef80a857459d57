//! Embeds the kernels' PTX, if `cargo xtask ptx` has written it: `EXACT` and `FAST` (the
//! `--cfg volpt_fast_math` build), each an `Option<&str>`.

use std::path::PathBuf;

fn main() {
    let dir = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo")).join("ptx");
    // A directory is watched recursively, so a PTX written later triggers a rebuild.
    println!("cargo:rerun-if-changed={}", dir.display());
    let embed = |file: &str| {
        let ptx = dir.join(file);
        if ptx.is_file() {
            format!("Some(include_str!({:?}))", ptx.display().to_string())
        } else {
            "None".to_owned()
        }
    };
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo")).join("ptx.rs");
    let source = format!(
        "pub const EXACT: Option<&str> = {};\npub const FAST: Option<&str> = {};\n",
        embed("volpt_kernels.ptx"),
        embed("volpt_kernels_fast.ptx")
    );
    std::fs::write(out, source).expect("OUT_DIR is writable");
}
