//! What packing a PTX module costs and gives: `cargo run --release -p volpt-cuda --example
//! pack-stats -- MODULE.ptx [ENTRY]`. Prints, for the whole module as one stream (zstd at several
//! levels, and gzip through flate2), and for the pack (`volpt_cuda::kernels::layout`) at both levels: the size,
//! the time to write it, the time to read all of it back, and to cut one kernel (ENTRY, by default
//! the module's first entry of its largest group) from the pack and from the whole text.
//!
//! Times are the median of 5 runs, on whatever else this machine runs at the time.

use std::io::{Read, Write};
use std::time::{Duration, Instant};

use volpt_cuda::entry::{ptx_entries, single_kernel_ptx};
use volpt_cuda::kernels::{layout, KernelPack};

const RUNS: usize = 5;

/// The median time of `RUNS` calls of `f`, and its last result.
fn timed<T>(mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut times = Vec::with_capacity(RUNS);
    let mut last = None;
    for _ in 0..RUNS {
        let start = Instant::now();
        last = Some(f());
        times.push(start.elapsed());
    }
    times.sort();
    (times[RUNS / 2], last.expect("RUNS > 0"))
}

fn row(what: &str, bytes: usize, of: usize, write: Duration, read: Duration) {
    println!(
        "{what:<28} {:>12} bytes  ratio {:>5.2}  write {:>8.2} s  read {:>8.1} ms",
        bytes,
        of as f64 / bytes as f64,
        write.as_secs_f64(),
        read.as_secs_f64() * 1e3
    );
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: pack-stats MODULE.ptx [ENTRY]")?;
    let ptx = std::fs::read_to_string(&path)?;
    println!(
        "{path}: {} bytes, {} entries",
        ptx.len(),
        ptx_entries(&ptx).len()
    );

    // The whole module as one stream: one write (slow levels take minutes), RUNS reads.
    for level in [3, 9, 12] {
        let start = Instant::now();
        let frame = zstd::encode_all(ptx.as_bytes(), level)?;
        let write = start.elapsed();
        let (read, text) = timed(|| zstd::decode_all(frame.as_slice()).expect("decodes"));
        assert_eq!(text, ptx.as_bytes());
        row(
            &format!("whole, zstd {level}"),
            frame.len(),
            ptx.len(),
            write,
            read,
        );
    }
    for (name, level) in [
        ("default", flate2::Compression::default()),
        ("best", flate2::Compression::best()),
    ] {
        let start = Instant::now();
        let mut encoder = flate2::write::GzEncoder::new(Vec::new(), level);
        encoder.write_all(ptx.as_bytes())?;
        let gz = encoder.finish()?;
        let write = start.elapsed();
        let (read, text) = timed(|| {
            let mut text = Vec::new();
            flate2::read::GzDecoder::new(gz.as_slice())
                .read_to_end(&mut text)
                .expect("decodes");
            text
        });
        assert_eq!(text, ptx.as_bytes());
        row(
            &format!("whole, gzip {name}"),
            gz.len(),
            ptx.len(),
            write,
            read,
        );
    }

    let mut packs = Vec::new();
    for level in [layout::DEV_LEVEL, layout::RELEASE_LEVEL] {
        let start = Instant::now();
        let bytes = layout::pack(&ptx, level)?;
        let write = start.elapsed();
        let pack = KernelPack::parse(&bytes)?;
        let (read, module) = timed(|| pack.module().expect("the pack reads back"));
        assert_eq!(module, ptx);
        row(
            &format!("pack, zstd {level}"),
            bytes.len(),
            ptx.len(),
            write,
            read,
        );
        packs.push(bytes);
    }
    // The release build's pack, as the binary carries it.
    let bytes = packs.pop().expect("two levels");
    let pack = KernelPack::parse(&bytes)?;

    let entry = match args.next() {
        Some(entry) => entry,
        None => {
            let split = layout::split(&ptx);
            let largest = split
                .entries
                .iter()
                .map(|e| layout::group_of(e.name))
                .max_by_key(|&group| {
                    split
                        .entries
                        .iter()
                        .filter(|e| layout::group_of(e.name) == group)
                        .map(|e| e.text.len())
                        .sum::<usize>()
                })
                .ok_or("the module has no entries")?;
            split
                .entries
                .iter()
                .find(|e| layout::group_of(e.name) == largest)
                .map(|e| e.name.to_owned())
                .expect("the group has an entry")
        }
    };
    let (parse, _) = timed(|| KernelPack::parse(&bytes).expect("parses"));
    let (from_pack, kernel) = timed(|| {
        pack.kernel(&entry, None)
            .expect("reads")
            .expect("has the entry")
    });
    let (from_text, cut) = timed(|| single_kernel_ptx(&ptx, &entry, None).expect("has the entry"));
    assert_eq!(kernel, cut);
    println!("one kernel, {entry}: {} bytes", kernel.len());
    println!(
        "  the pack's index read          {:>8.2} ms",
        parse.as_secs_f64() * 1e3
    );
    println!(
        "  cut from the pack              {:>8.2} ms",
        from_pack.as_secs_f64() * 1e3
    );
    println!(
        "  cut from the whole text        {:>8.2} ms",
        from_text.as_secs_f64() * 1e3
    );
    Ok(())
}
