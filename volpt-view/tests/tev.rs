//! `volpt view --tev`: the linear image streamed in tev's IPC format. A listener on 127.0.0.1:0
//! reads the packets as tev's `IpcPacket::interpretAs*` (src/Ipc.cpp of github.com/Tom94/tev)
//! does: a CreateImage of the film's size and three channels, then UpdateImageV3 bands that cover
//! every row, whose floats are the image's. A tev that goes and comes back gets the image created
//! again. (tev itself needs a display and no distribution here packages it: the packets are
//! checked against its reading code, field by field.)

use std::io::Read;
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::time::Duration;

use volpt::{BackendOptions, Image, RenderSettings, Scene};
use volpt_view::tev::{create_image, update_image};
use volpt_view::{ViewOptions, Viewer};

/// One packet as tev reads it.
#[derive(Debug, PartialEq)]
enum Packet {
    Create {
        name: String,
        width: i32,
        height: i32,
        channels: Vec<String>,
    },
    Update {
        name: String,
        channels: Vec<String>,
        rect: [i32; 4],
        offsets: Vec<i64>,
        strides: Vec<i64>,
        floats: Vec<f32>,
    },
}

/// tev's `IStream`: the fields in order, bounds checked.
struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn take(&mut self, n: usize) -> &[u8] {
        assert!(self.0.len() >= n, "the packet ends early");
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        head
    }
    fn u8(&mut self) -> u8 {
        self.take(1)[0]
    }
    fn i32(&mut self) -> i32 {
        i32::from_le_bytes(self.take(4).try_into().unwrap())
    }
    fn i64(&mut self) -> i64 {
        i64::from_le_bytes(self.take(8).try_into().unwrap())
    }
    fn string(&mut self) -> String {
        let end = self.0.iter().position(|&b| b == 0).expect("a NUL ends it");
        let s = String::from_utf8(self.take(end).to_vec()).unwrap();
        self.take(1);
        s
    }
}

fn parse(packet: &[u8]) -> Packet {
    let mut r = Reader(packet);
    assert_eq!(
        r.i32() as usize,
        packet.len(),
        "the length is the whole packet's"
    );
    let kind = r.u8();
    let _grab_focus = r.u8();
    let name = r.string();
    match kind {
        4 => {
            let (width, height, n) = (r.i32(), r.i32(), r.i32());
            let channels = (0..n).map(|_| r.string()).collect();
            assert!(r.0.is_empty(), "nothing after the channel names");
            Packet::Create {
                name,
                width,
                height,
                channels,
            }
        }
        6 => {
            let n = r.i32();
            let channels = (0..n).map(|_| r.string()).collect();
            let rect = [r.i32(), r.i32(), r.i32(), r.i32()];
            let offsets: Vec<i64> = (0..n).map(|_| r.i64()).collect();
            let strides: Vec<i64> = (0..n).map(|_| r.i64()).collect();
            let pixels = (rect[2] * rect[3]) as i64;
            let needed = (0..n as usize)
                .map(|c| offsets[c] + (pixels - 1) * strides[c] + 1)
                .max()
                .unwrap() as usize;
            assert_eq!(
                r.0.len(),
                needed * 4,
                "tev's size for the offsets and strides"
            );
            let floats =
                r.0.chunks_exact(4)
                    .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
                    .collect();
            Packet::Update {
                name,
                channels,
                rect,
                offsets,
                strides,
                floats,
            }
        }
        other => panic!("packet type {other}"),
    }
}

/// The image `packets` write, as tev assembles it.
fn assemble(packets: &[Packet]) -> Image {
    let Some(Packet::Create { width, height, .. }) = packets.first() else {
        panic!("a CreateImage first: {:?}", packets.first());
    };
    let (w, h) = (*width as u32, *height as u32);
    let mut image = Image {
        width: w,
        height: h,
        pixels: vec![[f32::NAN; 3]; (w * h) as usize],
    };
    for p in &packets[1..] {
        let Packet::Update {
            channels,
            rect: [x, y, pw, ph],
            offsets,
            strides,
            floats,
            ..
        } = p
        else {
            panic!("{p:?}")
        };
        assert_eq!(channels, &["R", "G", "B"]);
        for i in 0..(pw * ph) as usize {
            let (px, py) = (
                *x as usize + i % *pw as usize,
                *y as usize + i / *pw as usize,
            );
            for c in 0..3 {
                image.pixels[py * w as usize + px][c] =
                    floats[(offsets[c] + i as i64 * strides[c]) as usize];
            }
        }
    }
    image
}

#[test]
fn an_image_in_tev_packets_is_read_back_as_it_was() {
    // Wide enough that the floats take several bands.
    let (width, height) = (1500u32, 400u32);
    let image = Image {
        width,
        height,
        pixels: (0..width * height)
            .map(|i| [i as f32, -(i as f32), 0.5 * i as f32])
            .collect(),
    };
    let mut packets = vec![parse(&create_image("name", width, height))];
    let bands = update_image("name", &image);
    assert!(bands.len() > 1, "{} bands", bands.len());
    packets.extend(bands.iter().map(|b| parse(b)));
    let Packet::Create { name, channels, .. } = &packets[0] else {
        unreachable!()
    };
    assert_eq!((name.as_str(), channels.len()), ("name", 3));
    assert_eq!(
        assemble(&packets),
        image,
        "every pixel written once, as it was"
    );
}

/// Reads packets from `tev` until one has come since the CreateImage for every row of the image.
fn read_image(tev: &mut TcpStream) -> Image {
    let mut packets = Vec::new();
    loop {
        let mut len = [0u8; 4];
        tev.read_exact(&mut len).expect("a packet");
        let mut packet = len.to_vec();
        packet.resize(u32::from_le_bytes(len) as usize, 0);
        tev.read_exact(&mut packet[4..])
            .expect("the packet's bytes");
        let packet = parse(&packet);
        if matches!(packet, Packet::Create { .. }) {
            packets.clear();
        }
        packets.push(packet);
        if let Some(Packet::Create { height, .. }) = packets.first() {
            let rows: i32 = packets[1..]
                .iter()
                .map(|p| match p {
                    Packet::Update { rect, .. } => rect[3],
                    _ => 0,
                })
                .sum();
            if rows >= *height {
                return assemble(&packets);
            }
        }
    }
}

#[test]
fn volpt_view_streams_its_image_to_tev_and_again_after_tev_comes_back() {
    let tev = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = tev.local_addr().unwrap();
    let scene = Scene::load(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml"),
        &RenderSettings {
            resolution: Some((24, 20)),
            spp: Some(4),
            threads: Some(1),
            ..RenderSettings::default()
        },
    )
    .unwrap();
    let runtime = tokio::runtime::Runtime::new().unwrap();
    let viewer = runtime
        .block_on(Viewer::start(
            scene,
            ViewOptions {
                bind: "127.0.0.1:0".parse().unwrap(),
                backend: BackendOptions::default(),
                token: false,
                tev: Some(addr.to_string()),
            },
        ))
        .unwrap();
    tev.set_nonblocking(true).unwrap();
    let accept = || {
        let deadline = std::time::Instant::now() + Duration::from_secs(30);
        loop {
            match tev.accept() {
                Ok((stream, _)) => return stream,
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                    assert!(
                        std::time::Instant::now() < deadline,
                        "the viewer did not connect"
                    );
                    std::thread::sleep(Duration::from_millis(20));
                }
                Err(e) => panic!("{e}"),
            }
        }
    };
    for connection in 0..2 {
        // No page is open: the renderer renders for tev alone.
        let mut stream = accept();
        stream.set_nonblocking(false).unwrap();
        stream
            .set_read_timeout(Some(Duration::from_secs(30)))
            .unwrap();
        let image = read_image(&mut stream);
        assert_eq!(
            (image.width, image.height),
            (24, 20),
            "connection {connection}"
        );
        assert!(
            image
                .pixels
                .iter()
                .flatten()
                .all(|v| v.is_finite() && *v >= 0.0),
            "connection {connection}: radiance, finite and >= 0"
        );
        assert!(
            image.pixels.iter().flatten().any(|v| *v > 0.0),
            "connection {connection}: not black"
        );
        // tev goes; the viewer connects again and creates the image anew.
        drop(stream);
    }
    runtime.block_on(viewer.shutdown()).unwrap();
}
