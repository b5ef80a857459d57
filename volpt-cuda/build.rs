//! Embeds the kernels' PTX, if `cargo xtask ptx` has written it, as `PTX: Option<&str>`.

use std::path::PathBuf;

fn main() {
    let dir = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo")).join("ptx");
    let ptx = dir.join("volpt_kernels.ptx");
    // A directory is watched recursively, so a PTX written later triggers a rebuild.
    println!("cargo:rerun-if-changed={}", dir.display());
    let source = if ptx.is_file() {
        format!("Some(include_str!({:?}))", ptx.display().to_string())
    } else {
        "None".to_owned()
    };
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo")).join("ptx.rs");
    std::fs::write(out, format!("pub const PTX: Option<&str> = {source};\n"))
        .expect("OUT_DIR is writable");
}
