//! Project automation: `cargo xtask <task>`.
//!
//! - `ptx [PACKAGE]`: compiles a kernels crate with rustc's NVPTX backend. By default the workspace's
//!   (`volpt-kernels`), both builds at once, written to `volpt-cuda/ptx/volpt_kernels.ptx` and,
//!   built with fast math, `volpt_kernels_fast.ptx`, which `volpt-cuda` packs and embeds at its
//!   next build; any other kernels crate of the workspace (a library user's, see
//!   `docs/extending.md`) to `<its directory>/ptx/<crate>.ptx`.
//! - `ptx-selftests DIR`: only the selftest kernels of `volpt-kernels` (`--cfg
//!   volpt_selftests_only`), fast math, to `DIR/selftests_fast.ptx`: what `volpt selftest` needs
//!   (through `VOLPT_PTX`) to judge a mutant of volpt-core's GPU-only code in a minute instead
//!   of a full build (`scripts/gpu-mutants.sh`).
//! - `device-bundle`: the PTX, a release `volpt` with it embedded, the library-user example and its
//!   PTX, the scenes, the third-party data and the device scripts (`bench/device/*.sh`), in
//!   `bundle/` (git-ignored), ready to carry to the GPU machine.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context, Result};

fn main() -> Result<()> {
    let task = std::env::args().nth(1);
    match task.as_deref() {
        Some("ptx") => {
            let package = std::env::args().nth(2);
            ptx(package.as_deref().unwrap_or(KERNELS)).map(|_| ())
        }
        Some("ptx-selftests") => {
            let Some(dir) = std::env::args().nth(2) else {
                bail!("usage: cargo xtask ptx-selftests DIR");
            };
            ensure_rust_src()?;
            let built = ptx_build(KERNELS, Flavour::Fast, Only::Selftests)?;
            let dir = PathBuf::from(dir);
            std::fs::create_dir_all(&dir)?;
            let out = dir.join("selftests_fast.ptx");
            std::fs::copy(&built, &out)
                .with_context(|| format!("copying {} to {}", built.display(), out.display()))?;
            eprintln!("xtask: selftest kernels -> {}", out.display());
            Ok(())
        }
        Some("device-bundle") => device_bundle(),
        _ => {
            eprintln!("usage: cargo xtask <ptx [PACKAGE]|ptx-selftests DIR|device-bundle>");
            std::process::exit(2)
        }
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_owned()
}

fn run(cmd: &mut Command) -> Result<()> {
    eprintln!("xtask: {cmd:?}");
    let status = cmd.status().with_context(|| format!("starting {cmd:?}"))?;
    if !status.success() {
        bail!("{cmd:?} failed: {status}");
    }
    Ok(())
}

/// `core` must be rebuilt for nvptx64 (`-Zbuild-std`), which needs the standard library's source.
fn ensure_rust_src() -> Result<()> {
    let sysroot = Command::new("rustc")
        .args(["--print", "sysroot"])
        .output()?;
    let sysroot = PathBuf::from(String::from_utf8(sysroot.stdout)?.trim());
    if sysroot.join("lib/rustlib/src/rust/library/core").is_dir() {
        return Ok(());
    }
    run(Command::new("rustup").args(["component", "add", "rust-src"]))
}

/// The workspace's kernels crate, whose PTX `volpt-cuda` embeds.
const KERNELS: &str = "volpt-kernels";

/// The library-user example's kernels crate (`examples/smooth-ball`), carried to the device too.
const EXAMPLE_KERNELS: &str = "volpt-example-smooth-ball-kernels";

/// Builds the kernels crate `package` and returns the path of its PTX; the workspace's kernels
/// crate is built twice, exact and fast (`--math fast`), and the path of the exact PTX returned.
///
/// The two builds run at once: each spends most of its time in one LLVM thread (fat LTO, one
/// codegen unit) and peaks near 1 GB, so on two cores they take little longer than one.
fn ptx(package: &str) -> Result<PathBuf> {
    ensure_rust_src()?;
    if package != KERNELS {
        return ptx_build(package, Flavour::Exact, Only::All);
    }
    std::thread::scope(|scope| {
        let fast = scope.spawn(|| ptx_build(package, Flavour::Fast, Only::All));
        let exact = ptx_build(package, Flavour::Exact, Only::All);
        let fast = fast.join().expect("the fast build's thread does not panic");
        fast.context("the fast build")?;
        exact.context("the exact build")
    })
}

/// Which kernels of the crate: all, or (`volpt-kernels` only) the selftests alone, built apart
/// and not written where `volpt-cuda` embeds its PTX.
#[derive(Clone, Copy, PartialEq)]
enum Only {
    All,
    Selftests,
}

/// The kernels' arithmetic (`volpt_device::Math`).
#[derive(Clone, Copy, PartialEq)]
enum Flavour {
    Exact,
    Fast,
}

/// Builds the kernels crate `package` in `flavour` and returns the path of its PTX (the rust-src
/// component must be installed: [`ensure_rust_src`]).
///
/// Stable rustc with `RUSTC_BOOTSTRAP=1` (the `abi_ptx` feature); no linker is needed, because with
/// fat LTO `--emit=asm` writes the whole linked module as PTX. Only the kernels crate is asked for
/// assembly (`cargo rustc`): its dependencies, `core` among them, go into the module as bitcode, and
/// their own assembly would be written and never read. A separate target directory per flavour
/// keeps host builds, and the other flavour, from rebuilding `core`.
///
/// The fast flavour sets `volpt_fast_math` (approximate `lg2`, `ex2`, `sqrt` in `volpt_core::math`)
/// and lets LLVM's NVPTX backend use approximate division and square roots and fuse multiply-adds.
fn ptx_build(package: &str, flavour: Flavour, only: Only) -> Result<PathBuf> {
    let root = root();
    let (target_dir, flags, suffix) = match flavour {
        Flavour::Exact => (root.join("target-ptx"), "", ""),
        Flavour::Fast => (
            root.join("target-ptx/fast"),
            " --cfg volpt_fast_math -C llvm-args=-nvptx-prec-divf32=0 \
             -C llvm-args=-nvptx-prec-sqrtf32=0 -C llvm-args=-nvptx-fma-level=2",
            "_fast",
        ),
    };
    let (target_dir, only_flag) = match only {
        Only::All => (target_dir, ""),
        Only::Selftests => (target_dir.join("selftests"), " --cfg volpt_selftests_only"),
    };
    // Created here, not by cargo: the two flavours' builds run at once, and the fast one's
    // directory lies inside the exact one's, which cargo would create at the same moment (in a
    // fresh clone the fast build then failed to find its parent).
    std::fs::create_dir_all(&target_dir)
        .with_context(|| format!("creating {}", target_dir.display()))?;
    run(Command::new(env!("CARGO"))
        .current_dir(&root)
        .env("RUSTC_BOOTSTRAP", "1")
        .env(
            "CARGO_TARGET_NVPTX64_NVIDIA_CUDA_RUSTFLAGS",
            format!("-C target-cpu=sm_70{flags}{only_flag}"),
        )
        .env("CARGO_TARGET_NVPTX64_NVIDIA_CUDA_LINKER", "/bin/true")
        .args([
            "rustc",
            "-Zbuild-std=core",
            "--target",
            "nvptx64-nvidia-cuda",
        ])
        .args(["--profile", "nvptx", "-p", package, "--lib", "--target-dir"])
        .arg(&target_dir)
        .args(["--", "--emit=asm"]))?;
    let crate_name = package.replace('-', "_");
    let deps = target_dir.join("nvptx64-nvidia-cuda/nvptx/deps");
    let built = deps.join(format!("{crate_name}.s"));
    let ptx =
        std::fs::read_to_string(&built).with_context(|| format!("reading {}", built.display()))?;
    // Cargo takes the crate's output to be the linked `<crate>.ptx`, which `--emit=asm` with no
    // linker never writes: without it every build counts as stale and compiles the kernels again
    // (minutes), also when nothing changed. The assembly is that PTX; put it where cargo looks.
    let output = deps.join(format!("{crate_name}.ptx"));
    let _ = std::fs::remove_file(&output);
    std::fs::hard_link(&built, &output)
        .or_else(|_| std::fs::copy(&built, &output).map(|_| ()))
        .with_context(|| format!("writing {}", output.display()))?;
    let entries = ptx.lines().filter(|l| l.contains(".entry")).count();
    if entries == 0 {
        bail!("{} has no kernel entry points", built.display());
    }
    if only == Only::Selftests {
        return Ok(built);
    }
    let out = if package == KERNELS {
        root.join(format!("volpt-cuda/ptx/volpt_kernels{suffix}.ptx"))
    } else {
        package_dir(&root, package)?.join(format!("ptx/{crate_name}{suffix}.ptx"))
    };
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    // Rewrite only on change, so that an unchanged PTX does not rebuild volpt-cuda.
    if std::fs::read_to_string(&out).ok().as_deref() != Some(ptx.as_str()) {
        std::fs::write(&out, &ptx).with_context(|| format!("writing {}", out.display()))?;
    }
    eprintln!("xtask: {} kernels -> {}", entries, out.display());
    Ok(out)
}

/// The directory of workspace member `package`, from `cargo metadata`.
fn package_dir(root: &Path, package: &str) -> Result<PathBuf> {
    let output = Command::new(env!("CARGO"))
        .current_dir(root)
        .args(["metadata", "--format-version", "1", "--no-deps"])
        .output()
        .context("running cargo metadata")?;
    let metadata: serde_json::Value = serde_json::from_slice(&output.stdout)?;
    let manifest = metadata["packages"]
        .as_array()
        .into_iter()
        .flatten()
        .find(|p| p["name"] == package)
        .and_then(|p| p["manifest_path"].as_str())
        .with_context(|| format!("{package} is not a package of this workspace"))?;
    Ok(Path::new(manifest)
        .parent()
        .expect("a manifest lives in a directory")
        .to_owned())
}

fn copy_dir(from: &Path, to: &Path, skip: &dyn Fn(&Path) -> bool) -> Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let path = entry?.path();
        if skip(&path) {
            continue;
        }
        let dest = to.join(path.file_name().expect("directory entries have names"));
        if path.is_dir() {
            copy_dir(&path, &dest, skip)?;
        } else {
            std::fs::copy(&path, &dest).with_context(|| format!("copying {}", path.display()))?;
        }
    }
    Ok(())
}

/// `bundle/`: everything the GPU machine (which has no Rust) needs for `bundle/run.sh`.
fn device_bundle() -> Result<()> {
    let root = root();
    let example_ptx = ptx(EXAMPLE_KERNELS)?;
    let ptx = ptx(KERNELS)?;
    run(Command::new(env!("CARGO")).current_dir(&root).args([
        "build",
        "--release",
        "-p",
        "volpt-cli",
    ]))?;
    run(Command::new(env!("CARGO")).current_dir(&root).args([
        "build",
        "--release",
        "-p",
        "volpt-example-smooth-ball",
        "--example",
        "render",
    ]))?;
    // `volpt view`'s scripted client (bench/device/viewer.sh).
    run(Command::new(env!("CARGO")).current_dir(&root).args([
        "build",
        "--release",
        "-p",
        "volpt-view",
        "--example",
        "viewer_bench",
    ]))?;
    let bundle = root.join("bundle");
    if bundle.exists() {
        std::fs::remove_dir_all(&bundle)?;
    }
    std::fs::create_dir_all(bundle.join("bin"))?;
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), PathBuf::from);
    std::fs::copy(target.join("release/volpt"), bundle.join("bin/volpt"))?;
    std::fs::copy(
        target.join("release/examples/render"),
        bundle.join("bin/smooth-ball"),
    )?;
    std::fs::copy(
        target.join("release/examples/viewer_bench"),
        bundle.join("bin/viewer-bench"),
    )?;
    // Debug info is most of the binaries; the device carries at most 64 MiB.
    run(Command::new("strip").args([
        bundle.join("bin/volpt"),
        bundle.join("bin/smooth-ball"),
        bundle.join("bin/viewer-bench"),
    ]))?;
    // The binary embeds both kernel builds; the scripts' ptxas reports read these copies,
    // compressed (the device carries at most 64 MiB).
    for file in ["volpt_kernels.ptx", "volpt_kernels_fast.ptx"] {
        std::fs::copy(ptx.with_file_name(file), bundle.join(file))?;
        run(Command::new("gzip").arg("-9").arg(bundle.join(file)))?;
    }
    std::fs::copy(&example_ptx, bundle.join("smooth_ball_kernels.ptx"))?;
    // Generated grids are large and are regenerated on the device by `volpt scene generate`.
    copy_dir(&root.join("scenes"), &bundle.join("scenes"), &|p| {
        p.extension().is_some_and(|e| e == "vol")
    })?;
    // The large sparse VDB of bench/device/vdb.sh, written with OpenVDB beforehand
    // (`scenes/vdb/make_fixtures.py target/vdb-bench --large N`), if there is one.
    let vdb_bench = root.join("target/vdb-bench");
    if vdb_bench.is_dir() {
        // The carried bundle must stay small: a volume over 48 MiB is left out, said here.
        copy_dir(&vdb_bench, &bundle.join("vdb-bench"), &|p| {
            let large = p.metadata().is_ok_and(|m| m.len() > 48 << 20);
            if large {
                eprintln!(
                    "xtask: leaving {} (over 48 MiB) out of the bundle",
                    p.display()
                );
            }
            large || p.extension().is_none_or(|e| e != "vdb")
        })?;
    }
    let shared = root.join("../shared/data");
    if shared.is_dir() {
        copy_dir(&shared, &bundle.join("data"), &|_| false)?;
    } else {
        eprintln!(
            "xtask: warning: {} is missing; smoke and bucky will not load",
            shared.display()
        );
    }
    // Every device script: run.sh (checks and benchmark), stability.sh, accuracy.sh, ab.sh, and
    // their Python helpers (ptx_cut.py).
    for entry in std::fs::read_dir(root.join("bench/device"))? {
        let path = entry?.path();
        if path.extension().is_some_and(|e| e == "sh" || e == "py") {
            let name = path.file_name().expect("directory entries have names");
            std::fs::copy(&path, bundle.join(name))?;
        }
    }
    eprintln!("xtask: bundle ready in {}", bundle.display());
    Ok(())
}
