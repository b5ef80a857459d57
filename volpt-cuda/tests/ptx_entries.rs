//! The kernels this build embeds are exactly the registry's: every variant has an entry point for
//! every strategy, and the PTX holds no entry point that no variant uses (besides the selftests
//! and the tone mapping, which serve every variant); and the pack they are
//! embedded in gives back every kernel alone, and the whole PTX it was made of.
//!
//! CI builds the PTX (`cargo xtask ptx`) and sets `VOLPT_REQUIRE_PTX=1`, so a missing PTX fails
//! there; on a machine that never built the kernels the test says so and checks nothing.

use std::collections::BTreeSet;

use volpt_cuda::entry::{ptx_entries, registry_entries};
use volpt_cuda::kernels::{self, KernelPack, PackError};
use volpt_cuda::Math;

#[test]
fn the_exact_ptx_exports_exactly_the_registry() {
    exports_exactly_the_registry(Math::Exact);
}

#[test]
fn the_fast_ptx_exports_exactly_the_registry() {
    exports_exactly_the_registry(Math::Fast);
}

/// The embedded kernels built for `math`, or `None` (after saying so) if this build has none.
fn embedded(math: Math) -> Option<KernelPack<'static>> {
    let pack = kernels::embedded(math).unwrap_or_else(|e| panic!("the {math} kernels: {e}"));
    if pack.is_none() {
        assert!(
            std::env::var_os("VOLPT_REQUIRE_PTX").is_none(),
            "VOLPT_REQUIRE_PTX is set but this build embeds no {math} PTX: run `cargo xtask ptx` first"
        );
        eprintln!(
            "SKIPPED: this build embeds no {math} PTX (run `cargo xtask ptx`, then test again)"
        );
    }
    pack
}

fn exports_exactly_the_registry(math: Math) {
    let Some(pack) = embedded(math) else {
        return;
    };
    let exported: BTreeSet<&str> = pack.entries().collect();
    let registry = registry_entries();
    let registry: BTreeSet<&str> = registry
        .iter()
        .map(String::as_str)
        .chain(volpt_device::selftest::ENTRIES)
        .chain(volpt_device::tone::ENTRIES)
        .collect();
    let missing: Vec<_> = registry.difference(&exported).collect();
    let unused: Vec<_> = exported.difference(&registry).collect();
    assert!(missing.is_empty(), "variants without a kernel: {missing:?}");
    assert!(unused.is_empty(), "kernels no variant uses: {unused:?}");
}

/// The pack gives back the PTX that `cargo xtask ptx` wrote, byte for byte, with the pack's
/// entries in the module's order.
#[test]
fn the_packs_hold_the_ptx_they_were_made_of() {
    for math in Math::ALL.iter().copied() {
        let Some(pack) = embedded(math) else {
            continue;
        };
        let module = pack.module().unwrap_or_else(|e| panic!("{math}: {e}"));
        assert!(
            ptx_entries(&module).into_iter().eq(pack.entries()),
            "{math}"
        );
        let file = match math {
            Math::Exact => "volpt_kernels.ptx",
            Math::Fast => "volpt_kernels_fast.ptx",
        };
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("ptx")
            .join(file);
        // The build script packed this file; a change to it rebuilds the pack before the test.
        if let Ok(ptx) = std::fs::read_to_string(&path) {
            assert!(
                module == ptx,
                "{math}: the pack differs from {}",
                path.display()
            );
        }
    }
}

/// Every kernel of the registry comes out of the pack on its own (the renderer JIT-compiles one
/// kernel at a time): exactly that entry, the module's text of it, and the common text.
#[test]
fn every_kernel_compiles_alone() {
    for math in Math::ALL.iter().copied() {
        let Some(pack) = embedded(math) else {
            continue;
        };
        let module = pack.module().unwrap_or_else(|e| panic!("{math}: {e}"));
        for entry in registry_entries() {
            let alone = pack
                .kernel(&entry, Some(96))
                .unwrap_or_else(|e| panic!("{math}: {entry}: {e}"))
                .unwrap_or_else(|| panic!("{math}: {entry} not in the PTX"));
            assert_eq!(ptx_entries(&alone), [entry.as_str()]);
            assert_eq!(alone.matches(".maxnreg 96\n").count(), 1, "{entry}");
            assert!(
                alone.len() < module.len() / 10,
                "{entry}: {} bytes",
                alone.len()
            );
        }
    }
}

/// A pack damaged after the build fails with an error that says where, not with a panic or other
/// PTX: the middle byte of the embedded pack, in one of its frames, flipped.
#[test]
fn a_damaged_pack_says_so() {
    for math in Math::ALL.iter().copied() {
        let Some(bytes) = kernels::embedded_pack(math) else {
            continue;
        };
        let mut damaged = bytes.to_vec();
        damaged[bytes.len() / 2] ^= 0x20;
        let pack = KernelPack::parse(&damaged).unwrap_or_else(|e| panic!("{math}: {e}"));
        let error = pack.module().expect_err("a damaged frame decompresses");
        assert!(
            matches!(
                error,
                PackError::Decompress { .. } | PackError::Length { .. }
            ),
            "{math}: {error}"
        );
        assert!(error.to_string().contains("frame `"), "{math}: {error}");
    }
}

/// Local memory this test lets through today, pinned at the sizes measured (exact build,
/// 2026-11-28), so that any growth still fails; a regression to remove, not a design. Only two
/// kinds of chromatic kernel carry it: regeneration-2p-sk's two-path array holds 48 bytes more
/// with two chromatic paths (`HeroChannel`), and multi-kernel behind a rough dielectric under a
/// map 48 (40 until the boundary's hit record gained its shading normal, `BoxHit::shading`, which
/// both builds keep there beside the rest of the hit although a box never reads it). Grey
/// kernels carry none (their path state has no spectral part), chromatic kernels
/// that park paths none since the hero is a `u32` (a `u8` beside `r_u` cost them 8 bytes), and no
/// chromatic kernel keeps the scene there (the spectral shadow ray's second tracking closure cost
/// the index-matched ones up to 672).
fn known_debt(entry: &str) -> usize {
    if !entry.contains("__chromatic__") {
        return 0;
    }
    let two_paths = entry.starts_with("regeneration_2p_sk__");
    let rough_under_a_map = entry.starts_with("multi_kernel__")
        && entry.contains("__rough_dielectric__")
        && entry.ends_with("__lat_long");
    if two_paths || rough_under_a_map {
        48
    } else {
        0
    }
}

/// No kernel keeps per-thread state in local memory beyond the 64 bytes of the path counters'
/// final warp reduction (an array walked once, at the kernel's end). A larger local depot means
/// LLVM left a scene part behind a pointer: a call it did not inline takes the scene by address,
/// or a vector is indexed at run time. That cost cgg-logo 1.5x its time on an H100 (a 456-byte
/// frame from a grid lookup that was not inlined, `docs/strategies.md`).
///
/// Two kinds of kernel keep local memory by design: regeneration-2p-sk walks its two paths in an
/// array with a loop, so that one copy of the step's code serves both (`strategy::regeneration_2p_sk`
/// says why); its frame may hold those paths, no more. And the mesh kernels' BVH walk (one
/// out-of-line function, `volpt_core::shape::device_nearest`) keeps its bounded stack there.
#[test]
fn no_kernel_keeps_the_scene_in_local_memory() {
    const COUNTER_FLUSH_BYTES: usize = 64;
    // The counters' 64 bytes and 192 of two paths with their pixels and flags (256 in every
    // regeneration-2p-sk kernel of both builds, 2026-11-24).
    const TWO_PATH_ARRAY_BYTES: usize = 256;
    // The BVH walk's stack of far children (node index and entry distance), in the walk's own
    // frame.
    const BVH_STACK_BYTES: usize = volpt_core::mesh::MAX_BVH_DEPTH * size_of::<u64>();
    for math in Math::ALL.iter().copied() {
        let Some(pack) = embedded(math) else {
            continue;
        };
        let mut heavy = Vec::new();
        for entry in registry_entries() {
            let alone = pack
                .kernel(&entry, None)
                .unwrap_or_else(|e| panic!("{math}: {entry}: {e}"))
                .unwrap_or_else(|| panic!("{math}: {entry} not in the PTX"));
            let depot = kernel_local_depot_bytes(&alone, &entry);
            let base = if entry.starts_with("regeneration_2p_sk__") {
                TWO_PATH_ARRAY_BYTES
            } else if entry.starts_with("mesh__") {
                BVH_STACK_BYTES
            } else {
                COUNTER_FLUSH_BYTES
            };
            if depot > base + known_debt(&entry) {
                heavy.push(format!("{entry}: {depot} bytes"));
            }
        }
        assert!(
            heavy.is_empty(),
            "{math}: kernels with local memory: {heavy:?}"
        );
    }
}

/// The largest local depot of kernel `entry` in the module `ptx`: its own frame's and those of the
/// functions it calls, directly or not. A function of the module that the kernel never calls
/// (the mesh kernels' BVH walk, `volpt_core::shape::device_nearest`, in a box kernel's module) is
/// not its memory: ptxas's stack frame of the kernel counts its call graph alone.
fn kernel_local_depot_bytes(ptx: &str, entry: &str) -> usize {
    let bodies = function_bodies(ptx);
    let mut reached = vec![entry];
    let mut depot = 0;
    while let Some(name) = reached.pop() {
        let Some(body) = bodies.iter().find(|(n, _)| *n == name).map(|(_, b)| b) else {
            continue;
        };
        depot = depot.max(local_depot_bytes(body));
        for (callee, _) in &bodies {
            let called = body
                .lines()
                .any(|l| l.trim_start().starts_with("call") && l.contains(&format!(" {callee},")));
            if called && !reached.contains(callee) && *callee != name {
                reached.push(callee);
            }
        }
    }
    depot
}

/// The definitions of a PTX module's functions and entries: each name and its text, from its
/// directive's line to the body's closing `}` (declarations without a body are left out).
fn function_bodies(ptx: &str) -> Vec<(&str, String)> {
    let lines: Vec<&str> = ptx.lines().collect();
    let mut bodies = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        let directive = [".visible .entry ", ".entry ", ".visible .func ", ".func "]
            .iter()
            .find_map(|d| line.strip_prefix(d));
        let Some(mut rest) = directive else {
            i += 1;
            continue;
        };
        // A return value's parameter list comes before the name: `.func (.param .b64 r) name(`.
        rest = rest.trim_start();
        if rest.starts_with('(') {
            rest = rest.split_once(')').map_or("", |(_, r)| r).trim_start();
        }
        let name = rest.split('(').next().unwrap_or("").trim();
        // A body's `{` comes before any `;` ending a declaration.
        let start = i;
        let mut j = i;
        while j < lines.len() && lines[j] != "{" && !lines[j].trim_end().ends_with(';') {
            j += 1;
        }
        if j < lines.len() && lines[j] == "{" {
            while j < lines.len() && lines[j] != "}" {
                j += 1;
            }
            bodies.push((name, lines[start..=j.min(lines.len() - 1)].join("\n")));
        }
        i = j + 1;
    }
    bodies
}

/// The largest `.local ... __local_depotN[BYTES]` of a PTX text (0 without one).
fn local_depot_bytes(ptx: &str) -> usize {
    ptx.lines()
        .filter(|line| line.contains(".local") && line.contains("__local_depot"))
        .filter_map(|line| {
            let size = line.rsplit('[').next()?.split(']').next()?;
            size.parse::<usize>().ok()
        })
        .max()
        .unwrap_or(0)
}
