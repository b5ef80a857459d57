//! The progressive image streamed to the tev HDR viewer (`volpt view --tev HOST:PORT`), as pbrt-v4's
//! `--display-server` does: tev shows the linear radiance, with its own exposure, false colour and
//! pixel values, beside the browser's tone-mapped view.
//!
//! tev's IPC protocol (`src/Ipc.cpp` of github.com/Tom94/tev): each packet is a little-endian
//! `u32` length (the whole packet's, itself included), a type byte, then fields: `bool` as one
//! byte, integers and floats little-endian, strings NUL-terminated, arrays as their elements one
//! after the other. CreateImage (4): grab focus, name, width, height (`i32`), channel count
//! (`i32`), channel names. UpdateImageV3 (6): grab focus, name, channel count, channel names, x,
//! y, width, height (`i32`), each channel's offset and stride (`i64`, in floats), the floats.
//! tev replaces an image created again under the same name.

use std::sync::Arc;
use std::time::Duration;

use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;
use tokio::sync::watch;
use volpt::Image;

use crate::render::{Command, Commands, Shared};
use crate::ClientGuard;

const CREATE_IMAGE: u8 = 4;
const UPDATE_IMAGE_V3: u8 = 6;
const CHANNELS: [&str; 3] = ["R", "G", "B"];
/// Floats per update packet: tiles of whole rows, so that no packet grows with the image.
const FLOATS_PER_PACKET: usize = 1 << 20;
/// How long to wait before connecting again to a tev that is not (or no longer) there.
const RECONNECT: Duration = Duration::from_secs(2);

/// A packet being written: its length is patched in at the end.
struct Packet(Vec<u8>);

impl Packet {
    fn new(kind: u8, grab_focus: bool, name: &str) -> Self {
        let mut p = Packet(vec![0; 4]);
        p.0.push(kind);
        p.0.push(u8::from(grab_focus));
        p.string(name);
        p
    }

    fn string(&mut self, s: &str) {
        // tev reads up to the NUL: a name holding one would be cut there.
        self.0.extend(s.bytes().filter(|&b| b != 0));
        self.0.push(0);
    }

    fn i32(&mut self, v: i32) {
        self.0.extend(v.to_le_bytes());
    }

    fn i64(&mut self, v: i64) {
        self.0.extend(v.to_le_bytes());
    }

    /// The channel count and the channels' names, as both packets carry them.
    fn channels(&mut self) {
        self.i32(CHANNELS.len() as i32);
        for c in CHANNELS {
            self.string(c);
        }
    }

    fn finish(mut self) -> Vec<u8> {
        let len = u32::try_from(self.0.len()).expect("packets are at most a few MB");
        self.0[..4].copy_from_slice(&len.to_le_bytes());
        self.0
    }
}

/// The packet that (re)creates image `name` of `width` x `height` RGB pixels in tev.
pub fn create_image(name: &str, width: u32, height: u32) -> Vec<u8> {
    let mut p = Packet::new(CREATE_IMAGE, true, name);
    p.i32(width as i32);
    p.i32(height as i32);
    p.channels();
    p.finish()
}

/// The packets that write `image` into tev's image `name`: bands of whole rows, RGB interleaved
/// (channel `c` at offset `c`, stride 3).
pub fn update_image(name: &str, image: &Image) -> Vec<Vec<u8>> {
    let width = image.width.max(1) as usize;
    let rows_per_packet = (FLOATS_PER_PACKET / (3 * width)).max(1);
    image
        .pixels
        .chunks(rows_per_packet * width)
        .enumerate()
        .map(|(band, pixels)| {
            let mut p = Packet::new(UPDATE_IMAGE_V3, false, name);
            p.channels();
            let y = band * rows_per_packet;
            p.i32(0);
            p.i32(y as i32);
            p.i32(width as i32);
            p.i32((pixels.len() / width) as i32);
            for c in 0..CHANNELS.len() {
                p.i64(c as i64);
            }
            for _ in CHANNELS {
                p.i64(CHANNELS.len() as i64);
            }
            p.0.reserve(pixels.len() * 12);
            for v in pixels.iter().flatten() {
                p.0.extend(v.to_le_bytes());
            }
            p.finish()
        })
        .collect()
}

/// Streams every frame the renderer publishes (the newest, when tev reads slower than volpt
/// renders) to tev at `addr` as image `name`, connecting again when tev goes, until `shutdown`.
/// A connected tev counts as a client: the renderer renders for it with no page open.
pub(crate) async fn stream(
    addr: String,
    name: String,
    shared: Arc<Shared>,
    commands: Commands,
    mut shutdown: watch::Receiver<bool>,
) {
    let mut frames = shared.frames.subscribe();
    let mut warned = false;
    loop {
        let connection = tokio::select! {
            c = TcpStream::connect(&addr) => c,
            _ = shutdown.wait_for(|s| *s) => return,
        };
        let mut tev = match connection {
            Ok(tev) => {
                tracing::info!("tev: streaming to {addr} as {name:?}");
                warned = false;
                tev
            }
            Err(e) => {
                if !warned {
                    tracing::warn!(
                        "tev: cannot connect to {addr} ({e}); trying again every {RECONNECT:?}"
                    );
                    warned = true;
                }
                tokio::select! {
                    _ = tokio::time::sleep(RECONNECT) => continue,
                    _ = shutdown.wait_for(|s| *s) => return,
                }
            }
        };
        let _client = ClientGuard::new(&shared);
        let _ = commands.send(Command::Wake);
        // The frame on show when tev connects goes out first.
        frames.mark_changed();
        let mut size = None;
        let mut unread = [0u8; 64];
        loop {
            tokio::select! {
                changed = frames.changed() => if changed.is_err() { return },
                _ = shutdown.wait_for(|s| *s) => return,
                // tev sends nothing: a read ends only when it goes (a converged image publishes no
                // more frames, whose writes would find out).
                read = tev.read(&mut unread) => if matches!(read, Ok(0) | Err(_)) {
                    tracing::warn!("tev: {addr} closed the connection; connecting again");
                    break;
                },
            }
            let Some(frame) = frames.borrow_and_update().clone() else {
                continue;
            };
            let image = &frame.linear;
            let mut packets = Vec::new();
            if size != Some((image.width, image.height)) {
                packets.push(create_image(&name, image.width, image.height));
                size = Some((image.width, image.height));
            }
            packets.extend(update_image(&name, image));
            let mut sent = Ok(());
            for packet in &packets {
                sent = tev.write_all(packet).await;
                if sent.is_err() {
                    break;
                }
            }
            if let Err(e) = sent {
                tracing::warn!("tev: {addr} closed the connection ({e}); connecting again");
                break;
            }
        }
    }
}
