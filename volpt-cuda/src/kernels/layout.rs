//! How the embedded kernels are laid out: a PTX module split into its entry points and the text
//! around them, and the pack that stores those pieces compressed.
//!
//! `volpt-cuda`'s build script writes packs with this file (`#[path]`), the library reads them
//! with it ([`super::KernelPack`]), so it uses `std` and `zstd` alone.
//!
//! A pack is
//!
//! ```text
//! MAGIC                        8 bytes
//! index length                 u64, little-endian
//! index                        a zstd frame of UTF-8 text, one record a line, tab-separated:
//!   frame <name> <compressed bytes> <text bytes>
//!   entry <name> <frame> <start> <length> <at>
//! frames                       zstd frames, one after the other, in the index's order
//! ```
//!
//! Frame 0 is the module's common text ([`Split::common`]); each further frame holds the entries
//! of one group ([`group_of`]), back to back. An entry is bytes `start..start + length` of its
//! frame's text and stood at byte `at` of the common text. Every frame, the index's too, carries
//! zstd's content checksum, so a corrupt pack fails to decompress instead of yielding other PTX.

use std::io::{self, Write};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// The first bytes of every pack (the last one is the layout's version).
pub const MAGIC: &[u8; 8] = b"volptPK1";

/// The zstd level of a release build's frames: what the binary carries. At 19 zstd's optimal
/// parser finds the repeats between a strategy's kernels that 12's lazy one misses: on the fast
/// build's 123 MB of PTX (2026-11-29) the frames take 22% less than at 12 (13 and 14 are no
/// smaller, 16 18% less, and `--long` windows do not help), for about 15 times the time to
/// write, which a release build pays once per kernel build. Reading a frame back stays tens
/// of milliseconds.
pub const RELEASE_LEVEL: i32 = 19;

/// The zstd level of other builds' frames (debug builds, tests without `--release`): seconds
/// to write where [`RELEASE_LEVEL`] takes minutes on two cores.
pub const DEV_LEVEL: i32 = 12;

/// The index's record kinds, its first field.
pub const FRAME_RECORD: &str = "frame";
pub const ENTRY_RECORD: &str = "entry";

/// The name of frame 0, the common text.
pub const COMMON_FRAME: &str = "common";

/// A PTX module split into its `.entry` directives and the text around them.
pub struct Split<'a> {
    /// Everything but the entries, in module order: the header, globals, shared variables,
    /// functions and comments. Every kernel needs all of it, or may.
    pub common: String,
    /// The entries, in module order.
    pub entries: Vec<SplitEntry<'a>>,
}

/// One entry point of a [`Split`] module.
pub struct SplitEntry<'a> {
    pub name: &'a str,
    /// From the `.entry` line to the body's closing `}` line, its newline included.
    pub text: &'a str,
    /// Where the entry stood in [`Split::common`]: a byte offset at a line's start, never smaller
    /// than the previous entry's.
    pub at: usize,
}

/// The entry point a line declares, if it is an `.entry` directive.
pub fn entry_name(line: &str) -> Option<&str> {
    line.split_once(".entry ")
        .map(|(_, rest)| rest.trim_end_matches(['(', ' ']).trim())
}

/// The lines of `text` with the byte offset each starts at; a line holds its newline, if any.
fn lines_at(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.split_inclusive('\n').scan(0, |start, line| {
        let at = *start;
        *start += line.len();
        Some((at, line))
    })
}

/// A line without its line break.
fn bare(line: &str) -> &str {
    line.trim_end_matches(['\n', '\r'])
}

/// Splits `ptx` into its entries and the text around them.
///
/// An entry runs from its `.entry` line through its parameter list (to the line `)`) and its body,
/// from the line `{` to the line `}`; blocks nested in the body are indented, so the first `}` at
/// the line's start closes it. An entry without its closing line runs to the module's end.
pub fn split(ptx: &str) -> Split<'_> {
    let mut common = String::new();
    let mut entries = Vec::new();
    // `ptx[..copied]` is in `common` or in an entry.
    let mut copied = 0;
    let mut lines = lines_at(ptx);
    while let Some((start, line)) = lines.next() {
        let Some(name) = entry_name(bare(line)) else {
            continue;
        };
        let mut in_body = false;
        let mut end = ptx.len();
        for (at, line) in lines.by_ref() {
            match bare(line) {
                "{" => in_body = true,
                "}" if in_body => {
                    end = at + line.len();
                    break;
                }
                _ => {}
            }
        }
        common.push_str(&ptx[copied..start]);
        entries.push(SplitEntry {
            name,
            text: &ptx[start..end],
            at: common.len(),
        });
        copied = end;
    }
    common.push_str(&ptx[copied..]);
    Split { common, entries }
}

/// One kernel as a module of its own: `common` with the entry `entry` back at byte `at`.
///
/// With `max_registers`, the entry gets a `.maxnreg` directive before its body: the JIT caps its
/// registers per thread there (spilling what does not fit). `at` must be a character boundary of
/// `common`, at most its length.
pub fn assemble(common: &str, at: usize, entry: &str, max_registers: Option<u32>) -> String {
    let cap = max_registers.map(|n| format!(".maxnreg {n}\n"));
    let mut out = String::with_capacity(common.len() + entry.len() + 16);
    out.push_str(&common[..at]);
    match cap {
        Some(cap) => {
            let body = lines_at(entry)
                .find(|&(_, line)| bare(line) == "{")
                .map_or(entry.len(), |(at, _)| at);
            out.push_str(&entry[..body]);
            out.push_str(&cap);
            out.push_str(&entry[body..]);
        }
        None => out.push_str(entry),
    }
    out.push_str(&common[at..]);
    out
}

/// The group an entry is stored with: the strategy, its name's first `__`-separated part (the
/// selftest kernels' `selftest`). The entries of one strategy share its code and compress together
/// as well as the whole module (10.17 against 10.15 MB, fast build), while one group, at most a
/// tenth of the module, decompresses in about a tenth of the time.
pub fn group_of(name: &str) -> &str {
    name.split_once("__").map_or(name, |(group, _)| group)
}

/// `text` as one zstd frame at `level`, with its content checksum.
fn compress(text: &str, level: i32) -> io::Result<Vec<u8>> {
    let mut encoder = zstd::stream::Encoder::new(Vec::new(), level)?;
    encoder.include_checksum(true)?;
    encoder.write_all(text.as_bytes())?;
    encoder.finish()
}

/// `texts`, each compressed, on as many threads as this machine has cores: the build script packs
/// some 180 MB of PTX at every kernel build.
fn compress_all(texts: &[String], level: i32) -> io::Result<Vec<Vec<u8>>> {
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<Option<io::Result<Vec<u8>>>>> =
        Mutex::new(texts.iter().map(|_| None).collect());
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(texts.len());
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(text) = texts.get(i) else { break };
                let frame = compress(text, level);
                done.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(frame);
            });
        }
    });
    done.into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .map(|frame| frame.expect("every text was taken by a worker"))
        .collect()
}

/// The pack of the PTX module `ptx` (the layout above), its frames at zstd level `level`
/// ([`RELEASE_LEVEL`], [`DEV_LEVEL`]).
pub fn pack(ptx: &str, level: i32) -> io::Result<Vec<u8>> {
    let split = split(ptx);
    let mut names = vec![COMMON_FRAME];
    let mut texts = vec![split.common.clone()];
    let mut entries = String::new();
    for entry in &split.entries {
        let group = group_of(entry.name);
        // Frame 0 is the common text, never a group, whatever the group's name.
        let frame = match names.iter().skip(1).position(|&name| name == group) {
            Some(i) => i + 1,
            None => {
                names.push(group);
                texts.push(String::new());
                names.len() - 1
            }
        };
        let text = &mut texts[frame];
        entries.push_str(&format!(
            "{ENTRY_RECORD}\t{}\t{frame}\t{}\t{}\t{}\n",
            entry.name,
            text.len(),
            entry.text.len(),
            entry.at
        ));
        text.push_str(entry.text);
    }
    let frames = compress_all(&texts, level)?;
    let mut index = String::new();
    for ((name, text), frame) in names.iter().zip(&texts).zip(&frames) {
        index.push_str(&format!(
            "{FRAME_RECORD}\t{name}\t{}\t{}\n",
            frame.len(),
            text.len()
        ));
    }
    index.push_str(&entries);
    let index = compress(&index, level)?;
    let mut out = Vec::with_capacity(16 + index.len() + frames.iter().map(Vec::len).sum::<usize>());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(index.len() as u64).to_le_bytes());
    out.extend_from_slice(&index);
    for frame in &frames {
        out.extend_from_slice(frame);
    }
    Ok(out)
}
