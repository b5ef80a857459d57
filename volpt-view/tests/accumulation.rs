//! The viewer's accumulation is a render: after N samples of a still view, reached through an
//! interactive drag away and back, an exposure change and batches of the renderer's own sizes,
//! its linear image (`/snapshot.exr`) is the image `volpt render` gives of that view at N
//! samples: bit for bit at the same seed (the same paths, summed in the same order), and in
//! expectation against a render of another seed (`volpt::metrics::z_test`), on the CPU.
//! `bench/device/viewer-frames.sh` makes the same comparisons on a GPU.

use std::io::{Read, Write};
use std::path::Path;
use std::time::{Duration, Instant};

use futures_util::{SinkExt, StreamExt};
use serde_json::{json, Value};
use tokio_tungstenite::tungstenite::Message;
use volpt::metrics::{z_test, Z_BOUND};
use volpt::{Backend, BackendOptions, Image, ParamValue, Quiet, RenderSettings, Scene};
use volpt_view::protocol::split_frame;
use volpt_view::{ViewOptions, Viewer};

const WAIT: Duration = Duration::from_secs(120);
/// Samples per pixel the still view accumulates.
const SPP: u32 = 24;
const SIZE: (u32, u32) = (64, 48);

type Client =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

fn scene(seed: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml");
    let mut scene = Scene::load(
        path,
        &RenderSettings {
            resolution: Some(SIZE),
            spp: Some(SPP),
            ..RenderSettings::default()
        },
    )
    .unwrap();
    scene.set("seed", ParamValue::Int(seed.into())).unwrap();
    scene
}

async fn send(ws: &mut Client, message: Value) {
    ws.send(Message::Text(message.to_string().into()))
        .await
        .unwrap();
}

/// The next frame whose header `accept`s, acknowledging every frame on the way; text messages
/// (notices) are skipped.
async fn frame_where(ws: &mut Client, accept: impl Fn(&Value) -> bool) -> Value {
    let deadline = Instant::now() + WAIT;
    loop {
        let message = tokio::time::timeout_at(deadline.into(), ws.next())
            .await
            .expect("no frame within the wait")
            .expect("the connection closed")
            .unwrap();
        if let Message::Binary(bytes) = message {
            let (header, _) = split_frame(&bytes).unwrap();
            let ack = json!({"type": "ack", "frame": header["frame"]});
            send(ws, ack).await;
            if accept(&header) {
                return header;
            }
        }
    }
}

fn vec3(v: &Value) -> [f32; 3] {
    let a = |i: usize| v[i].as_f64().unwrap() as f32;
    [a(0), a(1), a(2)]
}

fn snapshot_exr(addr: std::net::SocketAddr) -> Image {
    let mut stream = std::net::TcpStream::connect(addr).unwrap();
    stream.set_read_timeout(Some(WAIT)).unwrap();
    write!(
        stream,
        "GET /snapshot.exr HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut response = Vec::new();
    stream.read_to_end(&mut response).unwrap();
    assert!(response.starts_with(b"HTTP/1.1 200"), "snapshot refused");
    let body = response.windows(4).position(|w| w == b"\r\n\r\n").unwrap() + 4;
    let path = std::env::temp_dir().join(format!(
        "volpt-view-accumulation-{}.exr",
        std::process::id()
    ));
    std::fs::write(&path, &response[body..]).unwrap();
    let image = volpt::read_exr(&path, "the snapshot").unwrap();
    let _ = std::fs::remove_file(&path);
    image
}

/// `volpt render` of `scene`'s view as the viewer set it (the same calls, so the same camera
/// bits): its initial view's up and target, then the shown view's origin, target and fov.
fn render(mut scene: Scene, initial: &Value, shown: &Value) -> Image {
    let set = |scene: &mut Scene, key: &str, v: ParamValue| scene.set(key, v).unwrap();
    set(
        &mut scene,
        "camera.up",
        ParamValue::Vec3(vec3(&initial["up"])),
    );
    set(
        &mut scene,
        "camera.target",
        ParamValue::Vec3(vec3(&initial["target"])),
    );
    set(
        &mut scene,
        "camera.origin",
        ParamValue::Vec3(vec3(&shown["origin"])),
    );
    set(
        &mut scene,
        "camera.target",
        ParamValue::Vec3(vec3(&shown["target"])),
    );
    let fov = shown["fov"].as_f64().unwrap() as f32;
    set(&mut scene, "camera.fov", ParamValue::Float(fov));
    let mut film = scene.film();
    Backend::cpu()
        .render(&scene, &mut film, 0..SPP, &Quiet)
        .unwrap();
    film.image(SPP)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_still_views_accumulation_is_the_render_of_its_samples() {
    let viewer = Viewer::start(
        scene(0),
        ViewOptions {
            bind: "127.0.0.1:0".parse().unwrap(),
            backend: BackendOptions::default(),
            token: false,
            tev: None,
        },
    )
    .await
    .unwrap();
    let (mut ws, _) = tokio_tungstenite::connect_async(format!("ws://{}/ws", viewer.local_addr()))
        .await
        .unwrap();
    let first = frame_where(&mut ws, |_| true).await;
    let initial = first["view"].clone();
    // A drag away (interactive: a reduced resolution, one sample), then back, still.
    let o = vec3(&initial["origin"]);
    let away = [o[0] + 0.7 * o[2], o[1], o[2] - 0.7 * o[0]];
    let target = initial["target"].clone();
    let drag = json!({"type": "camera", "origin": away, "target": target, "interactive": true});
    send(&mut ws, drag).await;
    frame_where(&mut ws, |h| h["interactive"] == true).await;
    send(&mut ws, json!({"type": "exposure", "value": 1.0})).await;
    let back = json!({"type": "camera", "origin": initial["origin"], "target": target});
    send(&mut ws, back).await;
    let last = frame_where(&mut ws, |h| {
        h["interactive"] == false && h["spp"] == SPP && h["view"]["origin"] == initial["origin"]
    })
    .await;
    assert!(last["epoch"].as_u64() > first["epoch"].as_u64(), "{last}");
    let shown = snapshot_exr(viewer.local_addr());
    viewer.shutdown().await.unwrap();
    assert_eq!((shown.width, shown.height), SIZE);

    // The same seed: the same paths, added in sample order.
    let same = render(scene(0), &initial, &last["view"]);
    let differ = shown
        .pixels
        .iter()
        .zip(&same.pixels)
        .filter(|(a, b)| a.map(f32::to_bits) != b.map(f32::to_bits))
        .count();
    assert_eq!(
        differ, 0,
        "pixels of the viewer's image that differ from the render's"
    );

    // Another seed: independent estimates of one image.
    let other = render(scene(1), &initial, &last["view"]);
    let test = z_test(&shown, &other);
    eprintln!("against seed 1: {test:?}");
    assert!(
        test.worst_tile <= Z_BOUND && test.z.abs() <= Z_BOUND,
        "the viewer's image is not an estimate of the render's: {test:?}"
    );
}
