//! The kernels this build embeds, compressed: both builds (exact and fast) of the workspace's
//! kernels crate hold some 180 MB of PTX, which the build script packs into about a ninth
//! ([`layout`]).
//!
//! Each kernel is cut when it is first asked for, from the common text and the one frame that
//! holds it (one strategy's entries): the renderer JIT-compiles one kernel at a time anyway. A
//! frame, at most a tenth of the module, decompresses in some 20-30 ms, once per process: the
//! process's packs ([`shared`]) keep the frames they decompressed, and [`prefetch`] decompresses a
//! strategy's frame on another thread while the driver opens the GPU, so that the first render's
//! kernel is cut without waiting for it.

pub mod layout;

use std::io::Read;
use std::ops::Range;
use std::sync::OnceLock;

use thiserror::Error;
use volpt_device::{Math, Strategy};

use layout::{COMMON_FRAME, ENTRY_RECORD, FRAME_RECORD, MAGIC};

/// The kernels' packs, if `cargo xtask ptx` wrote their PTX before this crate was built.
mod embedded {
    include!(concat!(env!("OUT_DIR"), "/ptx.rs"));
}

/// The pack of the workspace's kernels built for `math`, if this build carries it.
pub fn embedded_pack(math: Math) -> Option<&'static [u8]> {
    match math {
        Math::Exact => embedded::EXACT,
        Math::Fast => embedded::FAST,
    }
}

/// The workspace's kernels built for `math`, if this build carries them.
pub fn embedded(math: Math) -> Result<Option<KernelPack<'static>>, PackError> {
    embedded_pack(math).map(KernelPack::parse).transpose()
}

/// Whether this build carries the workspace's kernels built for `math`.
pub fn is_embedded(math: Math) -> bool {
    embedded_pack(math).is_some()
}

/// The process's pack of the workspace's kernels built for `math`, if this build carries it: read
/// once, and shared by every renderer, so that a frame decompressed for one (or by [`prefetch`])
/// serves all.
pub fn shared(math: Math) -> Result<Option<&'static KernelPack<'static>>, PackError> {
    static PACKS: [OnceLock<Option<KernelPack<'static>>>; 2] = [OnceLock::new(), OnceLock::new()];
    let slot = &PACKS[match math {
        Math::Exact => 0,
        Math::Fast => 1,
    }];
    // A pack that does not parse is not kept: parsing it again says why.
    match slot.get_or_init(|| embedded(math).ok().flatten()) {
        Some(pack) => Ok(Some(pack)),
        None => embedded(math).map(|_| None),
    }
}

/// Decompresses, on a thread of its own, the common text and the frame of `strategy`'s kernels
/// in the process's pack for `math` ([`shared`]), and returns at once: called as the GPU opens
/// (a fifth of a second of the driver's), the first render of `strategy` finds its frame ready.
/// Does nothing without embedded kernels or with `VOLPT_PTX` set (the renderer then reads its
/// kernels from that file); a damaged pack is reported by the render that asks for its kernel.
pub fn prefetch(math: Math, strategy: Strategy) {
    if !is_embedded(math) || std::env::var_os(crate::renderer::PTX_OVERRIDE).is_some() {
        return;
    }
    std::thread::spawn(move || {
        if let Ok(Some(pack)) = shared(math) {
            let group = layout::group_of(strategy.entry_prefix());
            // An error here is the render's to report, when it asks for the kernel.
            let _ = pack.frame_text(COMMON_FRAME);
            let _ = pack.frame_text(group);
        }
    });
}

/// What is wrong with a kernel pack. A pack's every part carries a checksum, so these mean a pack
/// damaged after the build, or one not written by this version of [`layout::pack`].
#[derive(Debug, Error)]
pub enum PackError {
    #[error("not a kernel pack: it does not start with {MAGIC:?}")]
    NotAPack,
    #[error("the kernel pack ends at byte {len}, inside its {part} (bytes {range:?})")]
    Truncated {
        part: String,
        len: u64,
        range: Range<u64>,
    },
    #[error("the kernel pack has {0} bytes after its last frame")]
    TrailingBytes(u64),
    #[error("the kernel pack's {part} does not decompress: {source}")]
    Decompress {
        part: String,
        source: std::io::Error,
    },
    #[error(
        "the kernel pack's {part} holds {actual} bytes of text where its index says {expected}"
    )]
    Length {
        part: String,
        expected: u64,
        actual: u64,
    },
    #[error("the kernel pack's {part} is not UTF-8: {source}")]
    Utf8 {
        part: String,
        source: std::string::FromUtf8Error,
    },
    #[error("the kernel pack's index, line {line}: {problem}")]
    Index { line: usize, problem: String },
}

/// One zstd frame of a pack.
struct Frame<'a> {
    /// What it holds: [`COMMON_FRAME`] or a group ([`layout::group_of`]).
    name: String,
    bytes: &'a [u8],
    /// Its text's length in bytes.
    text_len: u64,
    /// Its text, once decompressed (`None`: it does not decompress).
    text: OnceLock<Option<String>>,
}

impl Frame<'_> {
    /// The frame's text, checked against its length and its checksum, decompressed on first use.
    /// A thread that asks while another decompresses it waits for that text.
    fn text(&self) -> Result<&str, PackError> {
        match self.text.get_or_init(|| self.decompress().ok()) {
            Some(text) => Ok(text),
            // Decompressing is deterministic: the second try fails as the first did, and says why.
            None => Err(self
                .decompress()
                .err()
                .unwrap_or_else(|| PackError::Decompress {
                    part: format!("frame `{}`", self.name),
                    source: std::io::Error::other("it failed once and then decompressed"),
                })),
        }
    }

    fn decompress(&self) -> Result<String, PackError> {
        decompress(self.bytes, Some(self.text_len), || {
            format!("frame `{}`", self.name)
        })
    }
}

/// One entry point of a pack.
struct Entry {
    name: String,
    /// Its frame, never 0 (the common text's).
    frame: usize,
    /// Its bytes in its frame's text.
    text: Range<usize>,
    /// Where it stands in the common text.
    at: usize,
    /// Its record's line in the index, for errors.
    line: usize,
}

/// A kernel pack ([`layout`]), read: its index, checked, over its frames, still compressed.
pub struct KernelPack<'a> {
    /// Frame 0 holds the common text, the others the entries.
    frames: Vec<Frame<'a>>,
    /// In module order.
    entries: Vec<Entry>,
}

impl<'a> KernelPack<'a> {
    /// Reads the pack `bytes`: its index, whose records are checked against each other and the
    /// frames' sizes; the frames are decompressed only when asked for.
    pub fn parse(bytes: &'a [u8]) -> Result<Self, PackError> {
        let mut reader = Reader { bytes, offset: 0 };
        if reader.take(MAGIC.len() as u64, "magic").ok() != Some(MAGIC.as_slice()) {
            return Err(PackError::NotAPack);
        }
        let length = reader.take(8, "index's length")?;
        let length = u64::from_le_bytes(length.try_into().expect("take returns 8 bytes"));
        let index = decompress(reader.take(length, "index")?, None, || "index".to_owned())?;
        let mut frames = Vec::new();
        let mut entries: Vec<Entry> = Vec::new();
        for (line, record) in (1..).zip(index.lines()) {
            let bad = |problem: String| PackError::Index { line, problem };
            let fields: Vec<&str> = record.split('\t').collect();
            match fields[..] {
                [FRAME_RECORD, name, compressed, text_len] => {
                    if frames.is_empty() && name != COMMON_FRAME {
                        return Err(bad(format!(
                            "the first frame is `{name}`, not the common text"
                        )));
                    }
                    let part = format!("frame `{name}`");
                    frames.push(Frame {
                        name: name.to_owned(),
                        bytes: reader.take(number(compressed).map_err(bad)?, &part)?,
                        text_len: number(text_len).map_err(bad)?,
                        text: OnceLock::new(),
                    });
                }
                [ENTRY_RECORD, name, frame, start, len, at] => {
                    let [frame, start, len, at] =
                        [frame, start, len, at].map(|n| number(n).and_then(index_size));
                    let (frame, start, len, at) = (
                        frame.map_err(bad)?,
                        start.map_err(bad)?,
                        len.map_err(bad)?,
                        at.map_err(bad)?,
                    );
                    let end = start
                        .checked_add(len)
                        .ok_or_else(|| bad(format!("{name}: its end overflows")))?;
                    let Some(text_len) =
                        frames.get(frame).filter(|_| frame > 0).map(|f| f.text_len)
                    else {
                        return Err(bad(format!(
                            "{name}: no frame {frame} of entries before it"
                        )));
                    };
                    if end as u64 > text_len {
                        return Err(bad(format!(
                            "{name}: bytes {start}..{end} of a frame of {text_len}"
                        )));
                    }
                    let common_len = frames[0].text_len;
                    if at as u64 > common_len || entries.last().is_some_and(|e| e.at > at) {
                        return Err(bad(format!("{name}: at byte {at} of a common text of {common_len}, before the entry above it")));
                    }
                    entries.push(Entry {
                        name: name.to_owned(),
                        frame,
                        text: start..end,
                        at,
                        line,
                    });
                }
                _ => return Err(bad(format!("not a record: {record:?}"))),
            }
        }
        if frames.is_empty() {
            return Err(PackError::Index {
                line: 0,
                problem: "no frames".to_owned(),
            });
        }
        match reader.bytes.len() {
            0 => Ok(Self { frames, entries }),
            n => Err(PackError::TrailingBytes(n as u64)),
        }
    }
}

impl KernelPack<'_> {
    /// The entry points, in module order.
    pub fn entries(&self) -> impl Iterator<Item = &str> {
        self.entries.iter().map(|entry| entry.name.as_str())
    }

    /// The module reduced to the kernel `entry`, as [`crate::entry::single_kernel_ptx`] cuts it
    /// from the whole module, or `None` if the pack has no such entry. Only the common text and
    /// the entry's frame are decompressed.
    pub fn kernel(
        &self,
        entry: &str,
        max_registers: Option<u32>,
    ) -> Result<Option<String>, PackError> {
        let Some(entry) = self.entries.iter().find(|e| e.name == entry) else {
            return Ok(None);
        };
        let common = self.frames[0].text()?;
        let frame = self.frames[entry.frame].text()?;
        let text = self.entry_text(entry, frame)?;
        self.check_at(entry, common)?;
        Ok(Some(layout::assemble(
            common,
            entry.at,
            text,
            max_registers,
        )))
    }

    /// The text of the frame `name` ([`COMMON_FRAME`] or a group, [`layout::group_of`]), or `None`
    /// if the pack has no such frame.
    pub fn frame_text(&self, name: &str) -> Result<Option<&str>, PackError> {
        self.frames
            .iter()
            .find(|frame| frame.name == name)
            .map(Frame::text)
            .transpose()
    }

    /// The whole module, every entry back in the common text: the PTX the pack was made of.
    pub fn module(&self) -> Result<String, PackError> {
        let texts = self
            .frames
            .iter()
            .map(Frame::text)
            .collect::<Result<Vec<_>, _>>()?;
        let common = texts[0];
        let mut module = String::with_capacity(texts.iter().map(|t| t.len()).sum());
        let mut copied = 0;
        for entry in &self.entries {
            self.check_at(entry, common)?;
            module.push_str(&common[copied..entry.at]);
            module.push_str(self.entry_text(entry, texts[entry.frame])?);
            copied = entry.at;
        }
        module.push_str(&common[copied..]);
        Ok(module)
    }

    /// `entry`'s text in `frame`, the text of its frame.
    fn entry_text<'t>(&self, entry: &Entry, frame: &'t str) -> Result<&'t str, PackError> {
        frame
            .get(entry.text.clone())
            .ok_or_else(|| PackError::Index {
                line: entry.line,
                problem: format!(
                    "{}: bytes {:?} of frame `{}` are not whole characters",
                    entry.name, entry.text, self.frames[entry.frame].name
                ),
            })
    }

    /// Checks that `entry` goes at a character boundary of the common text `common`.
    fn check_at(&self, entry: &Entry, common: &str) -> Result<(), PackError> {
        if common.is_char_boundary(entry.at) {
            return Ok(());
        }
        Err(PackError::Index {
            line: entry.line,
            problem: format!(
                "{}: byte {} of the common text is inside a character",
                entry.name, entry.at
            ),
        })
    }
}

/// A pack's bytes, read from the front.
struct Reader<'a> {
    bytes: &'a [u8],
    /// Where `bytes` start in the pack.
    offset: u64,
}

impl<'a> Reader<'a> {
    /// The next `len` bytes, which hold the pack's `part`.
    fn take(&mut self, len: u64, part: &str) -> Result<&'a [u8], PackError> {
        let Some(taken) = usize::try_from(len).ok().filter(|&n| n <= self.bytes.len()) else {
            return Err(PackError::Truncated {
                part: part.to_owned(),
                len: self.offset + self.bytes.len() as u64,
                range: self.offset..self.offset.saturating_add(len),
            });
        };
        let (taken, rest) = self.bytes.split_at(taken);
        self.bytes = rest;
        self.offset += len;
        Ok(taken)
    }
}

/// A number of the index.
fn number(field: &str) -> Result<u64, String> {
    field
        .parse()
        .map_err(|e| format!("{field:?} is not a number: {e}"))
}

/// A number of the index that counts bytes of text in memory.
fn index_size(n: u64) -> Result<usize, String> {
    usize::try_from(n).map_err(|_| format!("{n} bytes do not fit in memory"))
}

/// The text of the zstd frame `bytes`, the pack's `part`, which must be `expected` bytes long if
/// that is known.
fn decompress(
    bytes: &[u8],
    expected: Option<u64>,
    part: impl Fn() -> String,
) -> Result<String, PackError> {
    let decompress_error = |source| PackError::Decompress {
        part: part(),
        source,
    };
    let decoder = zstd::stream::Decoder::with_buffer(bytes).map_err(decompress_error)?;
    let mut text = Vec::new();
    // Reading stops one byte past the expected length: a longer frame is found out without
    // decompressing it all.
    decoder
        .take(expected.map_or(u64::MAX, |n| n.saturating_add(1)))
        .read_to_end(&mut text)
        .map_err(decompress_error)?;
    if let Some(expected) = expected.filter(|&n| n != text.len() as u64) {
        return Err(PackError::Length {
            part: part(),
            expected,
            actual: text.len() as u64,
        });
    }
    String::from_utf8(text).map_err(|source| PackError::Utf8 {
        part: part(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::entry::{ptx_entries, single_kernel_ptx};

    /// Two strategies' entries, interleaved, around a function, globals and shared variables.
    const MODULE: &str =
        "//\n.version 6.0\n.shared .align 8 .b64 s[5];\n.func f(\n)\n{\n\tret;\n}\n\
        \t// .globl\ta__x\n.visible .entry a__x(\n\t.param .u64 p\n)\n{\n\tcall f;\n}\n\
        .visible .entry b__x(\n\t.param .u64 p\n)\n{\n\t{\n\t}\n\tret;\n}\n.global .b8 g[1];\n\
        .visible .entry a__y(\n)\n{\n\tret;\n}\n.visible .entry selftest(\n)\n{\n}\n// end\n";

    fn packed() -> Vec<u8> {
        layout::pack(MODULE, layout::DEV_LEVEL).unwrap()
    }

    #[test]
    fn every_kernel_comes_out_as_the_whole_module_cut() {
        let bytes = packed();
        let pack = KernelPack::parse(&bytes).unwrap();
        assert!(pack.entries().eq(ptx_entries(MODULE)));
        assert_eq!(pack.frames.len(), 4, "common, a, b, selftest");
        for entry in ptx_entries(MODULE) {
            for cap in [None, Some(64)] {
                assert_eq!(
                    pack.kernel(entry, cap).unwrap(),
                    single_kernel_ptx(MODULE, entry, cap),
                    "{entry} {cap:?}"
                );
            }
        }
        assert_eq!(pack.kernel("c__z", None).unwrap(), None);
        assert_eq!(pack.module().unwrap(), MODULE);
    }

    #[test]
    fn a_module_without_entries_packs_too() {
        let bytes = layout::pack(".version 6.0\n", layout::DEV_LEVEL).unwrap();
        let pack = KernelPack::parse(&bytes).unwrap();
        assert_eq!(pack.entries().count(), 0);
        assert_eq!(pack.module().unwrap(), ".version 6.0\n");
    }

    /// Every truncated pack is an error, whether at reading or at decompressing.
    #[test]
    fn a_truncated_pack_is_an_error() {
        let bytes = packed();
        for len in 0..bytes.len() {
            let read = KernelPack::parse(&bytes[..len]).and_then(|pack| pack.module());
            assert!(read.is_err(), "{len} of {} bytes read", bytes.len());
        }
        let error = KernelPack::parse(&bytes[..bytes.len() - 1])
            .err()
            .unwrap()
            .to_string();
        assert!(
            error.starts_with("the kernel pack ends at byte") && error.contains("frame `selftest`"),
            "{error}"
        );
    }

    /// Any byte of a pack changed gives an error, never a panic nor other PTX (a few bits of a
    /// zstd frame's header, e.g. its window size, do not change the text).
    #[test]
    fn a_damaged_pack_is_an_error() {
        let bytes = packed();
        for at in 0..bytes.len() {
            for flip in [0x01, 0x80] {
                let mut damaged = bytes.clone();
                damaged[at] ^= flip;
                match KernelPack::parse(&damaged).and_then(|pack| pack.module()) {
                    Ok(module) => assert_eq!(module, MODULE, "byte {at} ^ {flip:#x}"),
                    Err(error) => assert!(error.to_string().contains("kernel pack"), "{error}"),
                }
            }
        }
        let mut extended = bytes.clone();
        extended.push(0);
        assert_eq!(
            KernelPack::parse(&extended).err().unwrap().to_string(),
            "the kernel pack has 1 bytes after its last frame"
        );
        assert!(matches!(
            KernelPack::parse(b"PK\x03\x04"),
            Err(PackError::NotAPack)
        ));
    }

    #[test]
    fn a_frame_decompresses_once_and_serves_every_kernel_of_it() {
        let bytes = packed();
        let pack = KernelPack::parse(&bytes).unwrap();
        let first = pack.frame_text("a").unwrap().unwrap();
        assert!(first.contains(".entry a__x") && first.contains(".entry a__y"));
        let again = pack.frame_text("a").unwrap().unwrap();
        assert_eq!(
            first.as_ptr(),
            again.as_ptr(),
            "the same text, not a second copy"
        );
        assert_eq!(pack.frame_text("c").unwrap(), None);
        // Decompressed on several threads at once, a frame is still one text.
        let pack = KernelPack::parse(&bytes).unwrap();
        let texts: Vec<usize> = std::thread::scope(|threads| {
            let handles: Vec<_> = (0..4)
                .map(|_| threads.spawn(|| pack.frame_text("b").unwrap().unwrap().as_ptr() as usize))
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert!(texts.iter().all(|&t| t == texts[0]), "{texts:?}");
        assert_eq!(
            pack.kernel("b__x", None).unwrap(),
            single_kernel_ptx(MODULE, "b__x", None)
        );
    }

    #[test]
    fn a_damaged_frame_is_an_error_every_time_it_is_asked_for() {
        let bytes = packed();
        let pack = KernelPack::parse(&bytes).unwrap();
        let b = pack.frames.iter().find(|f| f.name == "b").unwrap();
        // The last byte of frame `b`: inside its content checksum.
        let end = b.bytes.as_ptr() as usize - bytes.as_ptr() as usize + b.bytes.len();
        let mut damaged = bytes.clone();
        damaged[end - 1] ^= 0x55;
        let pack = KernelPack::parse(&damaged).unwrap();
        for _ in 0..2 {
            let error = pack.kernel("b__x", None).unwrap_err().to_string();
            assert!(error.contains("frame `b`"), "{error}");
        }
        assert!(
            pack.kernel("a__x", None).unwrap().is_some(),
            "other frames still serve"
        );
    }

    /// A pack of `index` (its lines) and frames of `texts`.
    fn pack_of(index: &[&str], texts: &[&str]) -> Vec<u8> {
        let frame = |text: &str| zstd::encode_all(text.as_bytes(), 1).unwrap();
        let index = frame(&index.join("\n"));
        let mut bytes = MAGIC.to_vec();
        bytes.extend((index.len() as u64).to_le_bytes());
        bytes.extend(index);
        for text in texts {
            bytes.extend(frame(text));
        }
        bytes
    }

    /// The index's records are checked against each other; an error names the line and the entry.
    #[test]
    fn an_inconsistent_index_is_an_error() {
        let common = "c\n";
        // 19 bytes.
        let entries = ".entry a__x(\n)\n{\n}\n";
        // A frame's record: its compressed length from `text`, its text's length `text_len`.
        let frame = |name: &str, text: &str, text_len: usize| {
            let len = zstd::encode_all(text.as_bytes(), 1).unwrap().len();
            format!("frame\t{name}\t{len}\t{text_len}")
        };
        let read = |entry: &str, texts: [&str; 2]| {
            let index = [
                frame("common", texts[0], common.len()),
                frame("a", texts[1], entries.len()),
                entry.to_owned(),
            ];
            let index: Vec<&str> = index.iter().map(String::as_str).collect();
            KernelPack::parse(&pack_of(&index, &texts)).and_then(|pack| pack.module())
        };
        let texts = [common, entries];
        let good = "entry\ta__x\t1\t0\t19\t2";
        assert_eq!(read(good, texts).unwrap(), "c\n.entry a__x(\n)\n{\n}\n");
        for (entry, problem) in [
            (
                "entry\ta__x\t0\t0\t19\t2",
                "a__x: no frame 0 of entries before it",
            ),
            (
                "entry\ta__x\t2\t0\t19\t2",
                "a__x: no frame 2 of entries before it",
            ),
            (
                "entry\ta__x\t1\t1\t19\t2",
                "a__x: bytes 1..20 of a frame of 19",
            ),
            (
                "entry\ta__x\t1\t0\t19\t3",
                "a__x: at byte 3 of a common text of 2",
            ),
            ("entry\ta__x\t1\tx\t19\t2", "\"x\" is not a number"),
            ("entry\ta__x\t1\t0\t19", "not a record"),
        ] {
            let error = read(entry, texts).err().unwrap().to_string();
            assert!(
                error.starts_with("the kernel pack's index, line 3: ") && error.contains(problem),
                "{entry}: {error}"
            );
        }
        let error = read(good, ["c\r\n", entries]).err().unwrap();
        assert_eq!(
            error.to_string(),
            "the kernel pack's frame `common` holds 3 bytes of text where its index says 2"
        );
    }
}
