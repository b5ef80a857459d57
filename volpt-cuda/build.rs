//! Embeds the kernels, if `cargo xtask ptx` has written their PTX: each build's module (exact, and
//! fast: `--cfg volpt_fast_math`) packed by `src/kernels/layout.rs` into `OUT_DIR`, and `EXACT`
//! and `FAST`, each an `Option<&[u8]>` of its pack (zstd level by profile: `layout::RELEASE_LEVEL`
//! in release builds, `layout::DEV_LEVEL` elsewhere).

use std::path::PathBuf;

// The writing half of the layout; the library reads packs with the rest.
#[allow(dead_code)]
#[path = "src/kernels/layout.rs"]
mod layout;

/// Each build's constant and PTX file, as `cargo xtask ptx` names it.
const BUILDS: [(&str, &str); 2] = [
    ("EXACT", "volpt_kernels.ptx"),
    ("FAST", "volpt_kernels_fast.ptx"),
];

fn main() {
    let dir = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo")).join("ptx");
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo"));
    // A directory is watched recursively, so a PTX written later triggers a rebuild.
    println!("cargo:rerun-if-changed={}", dir.display());
    // The binary's size is the release build's: its frames get the slow, small level.
    let level = match std::env::var("PROFILE").as_deref() {
        Ok("release") => layout::RELEASE_LEVEL,
        _ => layout::DEV_LEVEL,
    };
    let mut source = String::new();
    for (constant, file) in BUILDS {
        let ptx = dir.join(file);
        let value = if ptx.is_file() {
            let text = std::fs::read_to_string(&ptx)
                .unwrap_or_else(|e| panic!("reading {}: {e}", ptx.display()));
            let pack = layout::pack(&text, level)
                .unwrap_or_else(|e| panic!("packing {}: {e}", ptx.display()));
            let packed = out.join(format!("{file}.pack"));
            std::fs::write(&packed, pack)
                .unwrap_or_else(|e| panic!("writing {}: {e}", packed.display()));
            format!("Some(include_bytes!({:?}))", packed.display().to_string())
        } else {
            "None".to_owned()
        };
        source.push_str(&format!("pub const {constant}: Option<&[u8]> = {value};\n"));
    }
    std::fs::write(out.join("ptx.rs"), source).expect("OUT_DIR is writable");
}
