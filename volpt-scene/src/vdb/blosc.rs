//! Blosc 1 chunks, as OpenVDB writes leaf and tile values by default (`COMPRESS_BLOSC`: LZ4 with
//! byte shuffling). Decoded in Rust (LZ4 blocks by `lz4_flex`, zlib by `flate2`) rather than by
//! the C library, so that a hostile chunk can make this return an error but not read or write out
//! of bounds. The format: c-blosc's `README_HEADER.rst` and `blosc.c` (`blosc_d`).

use std::io::Read;

/// Header flags (byte 2).
const DOSHUFFLE: u8 = 0x1;
const MEMCPYED: u8 = 0x2;
const DOBITSHUFFLE: u8 = 0x4;
const DONT_SPLIT: u8 = 0x10;
/// Blocks of at most this many values per type are split into one stream per byte of a value.
const MAX_SPLITS: usize = 16;
const MIN_BUFFERSIZE: usize = 128;
const HEADER: usize = 16;

/// Decodes a blosc chunk into exactly `expected` bytes. OpenVDB pads tiny buffers before
/// compressing them, so a chunk may hold more than `expected` (up to `expected.max(256)`): the
/// rest is dropped. Errors say what is wrong, for the caller to put after the file and field.
pub fn decompress(chunk: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    if chunk.len() < HEADER {
        return Err(format!(
            "a blosc chunk of {} bytes has no 16-byte header",
            chunk.len()
        ));
    }
    let flags = chunk[2];
    let typesize = usize::from(chunk[3]);
    let word = |at: usize| u32::from_le_bytes(chunk[at..at + 4].try_into().unwrap()) as usize;
    let (nbytes, blocksize, cbytes) = (word(4), word(8), word(12));
    if nbytes < expected || nbytes > expected.max(256) {
        return Err(format!(
            "a blosc chunk holds {nbytes} bytes where {expected} were expected"
        ));
    }
    if cbytes != chunk.len() {
        return Err(format!(
            "a blosc chunk says it is {cbytes} bytes long but is {}",
            chunk.len()
        ));
    }
    let mut out = vec![0u8; nbytes];
    if flags & MEMCPYED != 0 {
        let data = chunk
            .get(HEADER..HEADER + nbytes)
            .ok_or("a stored (uncompressed) blosc chunk is truncated")?;
        out.copy_from_slice(data);
        out.truncate(expected);
        return Ok(out);
    }
    if flags & DOBITSHUFFLE != 0 {
        return Err("blosc bit-shuffling is not supported (OpenVDB writes byte shuffling)".into());
    }
    if expected == 0 {
        return Ok(Vec::new());
    }
    // Blosc never makes a block larger than the data; a header that says so would make the
    // block buffer below as large as it likes.
    if typesize == 0 || blocksize == 0 || blocksize > nbytes {
        return Err(format!(
            "a blosc chunk of {nbytes} bytes with blocks of {blocksize} bytes of {typesize}-byte \
             values"
        ));
    }
    let codec = (flags >> 5) & 0x7;
    let blocks = nbytes.div_ceil(blocksize);
    let starts = chunk
        .get(HEADER..HEADER + 4 * blocks)
        .ok_or("a blosc chunk's block offsets are truncated")?;
    let mut tmp = vec![0u8; blocksize];
    for (b, start) in starts.chunks_exact(4).enumerate() {
        let start = u32::from_le_bytes(start.try_into().unwrap()) as usize;
        let from = b * blocksize;
        let size = blocksize.min(nbytes - from);
        let leftover = size < blocksize;
        let splits = if flags & DONT_SPLIT == 0
            && typesize <= MAX_SPLITS
            && blocksize / typesize >= MIN_BUFFERSIZE
            && !leftover
        {
            typesize
        } else {
            1
        };
        let split_bytes = size / splits;
        let shuffled = flags & DOSHUFFLE != 0 && typesize > 1;
        let mut src = start;
        let dest: &mut [u8] = if shuffled {
            &mut tmp[..size]
        } else {
            &mut out[from..from + size]
        };
        for s in 0..splits {
            let len = chunk
                .get(src..src + 4)
                .map(|w| i32::from_le_bytes(w.try_into().unwrap()))
                .ok_or("a blosc block is truncated")?;
            src += 4;
            let len = usize::try_from(len).map_err(|_| "a blosc stream has a negative length")?;
            let stream = chunk
                .get(src..src + len)
                .ok_or("a blosc stream runs past the chunk")?;
            src += len;
            let target = &mut dest[s * split_bytes..(s + 1) * split_bytes];
            if len == split_bytes {
                target.copy_from_slice(stream);
            } else {
                decode_stream(codec, stream, target)?;
            }
        }
        if shuffled {
            unshuffle(typesize, &tmp[..size], &mut out[from..from + size]);
        }
    }
    out.truncate(expected);
    Ok(out)
}

/// One compressed stream into exactly `target.len()` bytes.
fn decode_stream(codec: u8, stream: &[u8], target: &mut [u8]) -> Result<(), String> {
    let n = match codec {
        1 => lz4_flex::block::decompress_into(stream, target)
            .map_err(|e| format!("a blosc LZ4 stream does not decode: {e}"))?,
        3 => {
            let mut decoder = flate2::read::ZlibDecoder::new(stream);
            let mut n = 0;
            while n < target.len() {
                match decoder.read(&mut target[n..]) {
                    Ok(0) => break,
                    Ok(k) => n += k,
                    Err(e) => return Err(format!("a blosc zlib stream does not decode: {e}")),
                }
            }
            n
        }
        0 => return Err("blosc's BloscLZ codec is not supported (OpenVDB writes LZ4)".into()),
        2 => return Err("blosc's Snappy codec is not supported (OpenVDB writes LZ4)".into()),
        4 => return Err("blosc's Zstandard codec is not supported (OpenVDB writes LZ4)".into()),
        c => return Err(format!("unknown blosc codec {c}")),
    };
    if n != target.len() {
        return Err(format!(
            "a blosc stream decodes to {n} bytes where {} were expected",
            target.len()
        ));
    }
    Ok(())
}

/// Undoes blosc's byte shuffle of one block: byte `j` of every value was stored together, in
/// value order; a tail shorter than a value was stored as it is.
fn unshuffle(typesize: usize, shuffled: &[u8], out: &mut [u8]) {
    let values = shuffled.len() / typesize;
    for j in 0..typesize {
        for i in 0..values {
            out[i * typesize + j] = shuffled[j * values + i];
        }
    }
    let tail = values * typesize;
    out[tail..].copy_from_slice(&shuffled[tail..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stored (memcpyed) chunk: header then the bytes.
    #[test]
    fn a_memcpyed_chunk_is_its_bytes() {
        let data: Vec<u8> = (0..40).collect();
        let mut chunk = vec![2, 1, MEMCPYED, 4];
        chunk.extend((40u32).to_le_bytes());
        chunk.extend((40u32).to_le_bytes());
        chunk.extend((56u32).to_le_bytes());
        chunk.extend(&data);
        assert_eq!(decompress(&chunk, 40).unwrap(), data);
        assert!(decompress(&chunk[..50], 40).is_err());
        assert!(decompress(&chunk, 1000).is_err());
    }

    #[test]
    fn unshuffle_inverts_the_byte_shuffle() {
        let original: Vec<u8> = (0..27).collect();
        let (ts, n) = (4, 27 / 4);
        let mut shuffled = vec![0; 27];
        for j in 0..ts {
            for i in 0..n {
                shuffled[j * n + i] = original[i * ts + j];
            }
        }
        shuffled[n * ts..].copy_from_slice(&original[n * ts..]);
        let mut out = vec![0; 27];
        unshuffle(ts, &shuffled, &mut out);
        assert_eq!(out, original);
    }

    #[test]
    fn hostile_headers_are_errors() {
        assert!(decompress(&[0; 8], 8).is_err());
        let mut chunk = vec![2, 1, DOSHUFFLE | (1 << 5), 4];
        chunk.extend((64u32).to_le_bytes());
        chunk.extend((u32::MAX).to_le_bytes());
        chunk.extend((20u32).to_le_bytes());
        chunk.extend([0xff; 4]);
        assert!(decompress(&chunk, 64).is_err());
    }
}
