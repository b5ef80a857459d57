//! The viewer's protocol end to end on the CPU: a real server on 127.0.0.1:0 and WebSocket
//! clients. Frames arrive and refine, a camera move starts a new epoch whose frames differ, bad
//! and oversize messages are refused without changing anything, tokens are required where they
//! must be, flow control holds frames back until acknowledged, two clients share one render, a
//! client that goes is forgotten, and shutdown closes connections.

use std::io::{Read, Write};
use std::path::Path;
use std::time::{Duration, Instant};

use futures_util::{SinkExt, StreamExt};
use serde_json::{json, Value};
use tokio::net::TcpStream;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::{MaybeTlsStream, WebSocketStream};
use volpt::{BackendOptions, RenderSettings, Scene};
use volpt_view::protocol::split_frame;
use volpt_view::{ViewOptions, Viewer};

type Client = WebSocketStream<MaybeTlsStream<TcpStream>>;

const WAIT: Duration = Duration::from_secs(30);

fn scene(spp: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml");
    Scene::load(
        path,
        &RenderSettings {
            resolution: Some((24, 20)),
            spp: Some(spp),
            threads: Some(1),
            ..RenderSettings::default()
        },
    )
    .unwrap()
}

async fn start(spp: u32, token: bool) -> Viewer {
    Viewer::start(
        scene(spp),
        ViewOptions {
            bind: "127.0.0.1:0".parse().unwrap(),
            backend: BackendOptions::default(),
            token,
            tev: None,
        },
    )
    .await
    .unwrap()
}

fn ws_url(viewer: &Viewer, token: Option<&str>) -> String {
    let addr = viewer.local_addr();
    match token {
        Some(t) => format!("ws://{addr}/ws?token={t}"),
        None => format!("ws://{addr}/ws"),
    }
}

async fn connect(viewer: &Viewer) -> Client {
    let (mut ws, _) = tokio_tungstenite::connect_async(ws_url(viewer, viewer.token()))
        .await
        .unwrap();
    let hello = next_text(&mut ws).await;
    assert_eq!(hello["type"], "hello", "{hello}");
    ws
}

/// What a client receives: a JSON text message, or a frame's header and image.
enum Received {
    Text(Value),
    Frame(Value, Vec<u8>),
    Closed(Option<u16>),
}

async fn receive(ws: &mut Client) -> Received {
    let message = tokio::time::timeout(WAIT, ws.next())
        .await
        .expect("no message within the wait");
    match message {
        Some(Ok(Message::Text(t))) => Received::Text(serde_json::from_str(&t).unwrap()),
        Some(Ok(Message::Binary(b))) => {
            let (header, image) = split_frame(&b).expect("a frame message");
            Received::Frame(header, image.to_vec())
        }
        Some(Ok(Message::Close(frame))) => Received::Closed(frame.map(|f| f.code.into())),
        Some(Ok(other)) => panic!("unexpected {other:?}"),
        None | Some(Err(_)) => Received::Closed(None),
    }
}

async fn next_text(ws: &mut Client) -> Value {
    loop {
        match receive(ws).await {
            Received::Text(v) => return v,
            Received::Frame(h, _) => ack(ws, &h).await,
            Received::Closed(code) => panic!("closed ({code:?}) while waiting for text"),
        }
    }
}

async fn ack(ws: &mut Client, header: &Value) {
    let message = json!({"type": "ack", "frame": header["frame"]}).to_string();
    ws.send(Message::Text(message.into())).await.unwrap();
}

/// The next frame for which `accept(header)` holds, acknowledging every frame on the way.
async fn frame_where(ws: &mut Client, accept: impl Fn(&Value) -> bool) -> (Value, Vec<u8>) {
    let deadline = Instant::now() + WAIT;
    while Instant::now() < deadline {
        match receive(ws).await {
            Received::Frame(h, image) => {
                ack(ws, &h).await;
                if accept(&h) {
                    return (h, image);
                }
            }
            Received::Text(v) => panic!("unexpected text {v}"),
            Received::Closed(code) => panic!("closed ({code:?}) while waiting for a frame"),
        }
    }
    panic!("no such frame within the wait");
}

async fn send(ws: &mut Client, message: Value) {
    ws.send(Message::Text(message.to_string().into()))
        .await
        .unwrap();
}

fn moved_origin(header: &Value) -> Vec<f64> {
    let o: Vec<f64> = serde_json::from_value(header["view"]["origin"].clone()).unwrap();
    vec![o[0] * 0.5 - o[2], o[1], o[2] * 0.5 + o[0]]
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_frame_arrives_and_a_camera_move_gives_frames_of_a_new_epoch_that_differ() {
    let viewer = start(8, false).await;
    let mut ws = connect(&viewer).await;
    let (first, image) = frame_where(&mut ws, |_| true).await;
    assert!(image.starts_with(&[0xFF, 0xD8]), "a JPEG");
    assert_eq!(
        (first["width"].as_u64(), first["height"].as_u64()),
        (Some(24), Some(20))
    );
    // Progressive refinement: the same epoch gains samples.
    let (refined, _) = frame_where(&mut ws, |h| h["spp"].as_u64() > first["spp"].as_u64()).await;
    assert_eq!(refined["epoch"], first["epoch"]);

    let origin = moved_origin(&first);
    let target = first["view"]["target"].clone();
    send(
        &mut ws,
        json!({"type": "camera", "origin": origin, "target": target}),
    )
    .await;
    let epoch = first["epoch"].as_u64().unwrap();
    let (moved, moved_image) = frame_where(&mut ws, |h| h["epoch"].as_u64() > Some(epoch)).await;
    let got: Vec<f64> = serde_json::from_value(moved["view"]["origin"].clone()).unwrap();
    for (a, b) in got.iter().zip(&origin) {
        assert!((a - b).abs() < 1e-4, "{got:?} != {origin:?}");
    }
    assert_ne!(
        moved_image, image,
        "the moved camera's frame equals the first"
    );
    viewer.shutdown().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_messages_get_an_error_reply_and_change_nothing() {
    let viewer = start(2, false).await;
    let mut ws = connect(&viewer).await;
    let (first, _) = frame_where(&mut ws, |h| h["spp"] == 2).await;
    let target = first["view"]["target"].clone();
    let bad = [
        json!("not json").to_string(),
        "{\"type\":".to_owned(),
        json!({"type": "fly"}).to_string(),
        json!({"type": "camera", "origin": target, "target": target}).to_string(),
        json!({"type": "set", "key": "phase.g", "value": 2.0}).to_string(),
        json!({"type": "set", "key": "medium.albedo", "value": [1.5, 0, 0]}).to_string(),
        json!({"type": "set", "key": "camera.origin", "value": [1, 2, 3]}).to_string(),
        json!({"type": "set", "key": "max_depth", "value": "deep"}).to_string(),
        json!({"type": "ack", "frame": 123456}).to_string(),
        json!({"type": "exposure", "value": 1e9}).to_string(),
    ];
    for message in &bad {
        ws.send(Message::Text(message.clone().into()))
            .await
            .unwrap();
        let reply = next_text(&mut ws).await;
        assert_eq!(reply["type"], "error", "{message} got {reply}");
        assert!(reply["message"].as_str().is_some_and(|m| !m.is_empty()));
    }
    ws.send(Message::Binary(vec![1, 2, 3].into()))
        .await
        .unwrap();
    assert_eq!(next_text(&mut ws).await["type"], "error");
    // Still served, and nothing changed: an exposure change re-tone-maps the same epoch.
    send(&mut ws, json!({"type": "exposure", "value": 1.5})).await;
    let (after, _) = frame_where(&mut ws, |h| h["exposure"] == 1.5).await;
    assert_eq!(after["epoch"], first["epoch"]);
    assert_eq!(after["params"], first["params"]);
    assert_eq!(after["view"], first["view"]);
    viewer.shutdown().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_oversize_message_closes_that_connection_only() {
    let viewer = start(2, false).await;
    let mut ws = connect(&viewer).await;
    let big = format!("{{\"type\":\"reset\",\"pad\":\"{}\"}}", "x".repeat(10_000));
    let _ = ws.send(Message::Text(big.into())).await;
    let deadline = Instant::now() + WAIT;
    loop {
        assert!(Instant::now() < deadline, "the connection stayed open");
        match receive(&mut ws).await {
            Received::Closed(code) => {
                assert!(matches!(code, None | Some(1009)), "{code:?}");
                break;
            }
            Received::Frame(..) => {}
            Received::Text(v) => panic!("unexpected {v}"),
        }
    }
    // Others are still served.
    let mut other = connect(&viewer).await;
    frame_where(&mut other, |_| true).await;
    viewer.shutdown().await.unwrap();
}

/// A plain HTTP GET: status code and body.
fn http_get(addr: std::net::SocketAddr, path: &str, host: &str) -> (u16, Vec<u8>) {
    let mut stream = std::net::TcpStream::connect(addr).unwrap();
    stream.set_read_timeout(Some(WAIT)).unwrap();
    write!(
        stream,
        "GET {path} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut response = Vec::new();
    stream.read_to_end(&mut response).unwrap();
    let text = String::from_utf8_lossy(&response);
    let status = text.split(' ').nth(1).and_then(|s| s.parse().ok()).unwrap();
    let body = response
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .map_or(Vec::new(), |i| response[i + 4..].to_vec());
    (status, body)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_missing_or_wrong_token_is_refused_where_one_is_required() {
    let viewer = start(2, true).await;
    let token = viewer.token().unwrap().to_owned();
    assert!(viewer.url().contains(&token));
    let addr = viewer.local_addr();
    let host = addr.to_string();
    assert_eq!(http_get(addr, "/", &host).0, 403);
    assert_eq!(http_get(addr, "/?token=0123", &host).0, 403);
    assert_eq!(http_get(addr, "/snapshot.png", &host).0, 403);
    let (status, page) = http_get(addr, &format!("/?token={token}"), &host);
    assert_eq!(status, 200);
    assert!(String::from_utf8_lossy(&page).contains("<canvas"));
    for url in [ws_url(&viewer, None), ws_url(&viewer, Some("wrong"))] {
        let refused = tokio_tungstenite::connect_async(url).await;
        assert!(
            refused.is_err(),
            "a WebSocket without the token was accepted"
        );
    }
    let mut ws = connect(&viewer).await;
    frame_where(&mut ws, |_| true).await;
    viewer.shutdown().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_loopback_viewer_refuses_foreign_hosts_and_origins_and_serves_snapshots() {
    let viewer = start(2, false).await;
    let addr = viewer.local_addr();
    assert_eq!(http_get(addr, "/", "evil.example").0, 403);
    assert_eq!(
        http_get(addr, "/", &format!("localhost:{}", addr.port())).0,
        200
    );
    let mut request = ws_url(&viewer, None).into_client_request().unwrap();
    request
        .headers_mut()
        .insert("Origin", "http://evil.example".parse().unwrap());
    assert!(tokio_tungstenite::connect_async(request).await.is_err());

    let mut ws = connect(&viewer).await;
    frame_where(&mut ws, |h| h["spp"] == 2).await;
    let host = addr.to_string();
    let (status, exr) = http_get(addr, "/snapshot.exr", &host);
    assert_eq!(status, 200);
    assert!(exr.starts_with(&[0x76, 0x2f, 0x31, 0x01]), "OpenEXR magic");
    let (status, png) = http_get(addr, "/snapshot.png", &host);
    assert_eq!(status, 200);
    assert!(png.starts_with(b"\x89PNG"));
    // PNG frames on request.
    send(&mut ws, json!({"type": "format", "format": "png"})).await;
    let (_, image) = frame_where(&mut ws, |h| h["format"] == "png").await;
    assert!(image.starts_with(b"\x89PNG"));
    viewer.shutdown().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn frames_wait_for_acknowledgements_two_at_most() {
    // Many samples: the renderer publishes frame after frame while the client acknowledges none.
    let viewer = start(4096, false).await;
    let mut ws = connect(&viewer).await;
    let mut held = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(3);
    while let Ok(message) = tokio::time::timeout_at(deadline.into(), ws.next()).await {
        match message {
            Some(Ok(Message::Binary(b))) => held.push(split_frame(&b).unwrap().0),
            other => panic!("unexpected {other:?}"),
        }
    }
    assert_eq!(held.len(), 2, "frames without acknowledgement");
    ack(&mut ws, &held[0]).await;
    let (next, _) = frame_where(&mut ws, |_| true).await;
    assert!(next["frame"].as_u64() > held[1]["frame"].as_u64());
    viewer.shutdown().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn two_clients_watch_one_render_and_a_client_that_goes_is_forgotten() {
    let viewer = start(4, false).await;
    let mut a = connect(&viewer).await;
    let mut b = connect(&viewer).await;
    let (first, _) = frame_where(&mut a, |_| true).await;
    frame_where(&mut b, |_| true).await;
    assert_eq!(viewer.clients(), 2);
    let origin = moved_origin(&first);
    send(
        &mut a,
        json!({"type": "camera", "origin": origin, "target": first["view"]["target"]}),
    )
    .await;
    // B sees A's move: one render, one view.
    let epoch = first["epoch"].as_u64();
    let (seen, _) = frame_where(&mut b, |h| h["epoch"].as_u64() > epoch).await;
    let got: Vec<f64> = serde_json::from_value(seen["view"]["origin"].clone()).unwrap();
    assert!((got[0] - origin[0]).abs() < 1e-4);
    drop(a);
    let deadline = Instant::now() + WAIT;
    while viewer.clients() != 1 {
        assert!(
            Instant::now() < deadline,
            "the closed client is still counted"
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    drop(b);
    viewer.shutdown().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn shutdown_closes_connections_and_returns() {
    let viewer = start(4096, false).await;
    let mut ws = connect(&viewer).await;
    frame_where(&mut ws, |_| true).await;
    tokio::time::timeout(WAIT, viewer.shutdown())
        .await
        .expect("shutdown within the wait")
        .unwrap();
    loop {
        match receive(&mut ws).await {
            Received::Closed(code) => {
                assert!(matches!(code, None | Some(1001)), "{code:?}");
                break;
            }
            _ => continue,
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn parameters_and_reset_start_new_epochs_and_show_in_frames() {
    let viewer = start(2, false).await;
    let mut ws = connect(&viewer).await;
    let (first, _) = frame_where(&mut ws, |_| true).await;
    send(
        &mut ws,
        json!({"type": "set", "key": "medium.scale", "value": 0.5}),
    )
    .await;
    let (scaled, _) = frame_where(&mut ws, |h| h["params"]["medium_scale"] == 0.5).await;
    assert!(scaled["epoch"].as_u64() > first["epoch"].as_u64());
    send(
        &mut ws,
        json!({"type": "set", "key": "phase.g", "value": -0.3}),
    )
    .await;
    frame_where(&mut ws, |h| {
        (h["params"]["phase_g"].as_f64().unwrap() + 0.3).abs() < 1e-6
    })
    .await;
    let origin = moved_origin(&first);
    send(&mut ws, json!({"type": "camera", "origin": origin, "target": first["view"]["target"], "interactive": true})).await;
    let (dragging, _) = frame_where(&mut ws, |h| h["interactive"] == true).await;
    assert!(
        dragging["width"].as_u64() < Some(24),
        "a reduced resolution while dragging"
    );
    // The drag ends by itself when moves stop: full resolution again.
    let (still, _) = frame_where(&mut ws, |h| h["interactive"] == false && h["width"] == 24).await;
    assert_eq!(still["view"]["origin"], dragging["view"]["origin"]);
    send(&mut ws, json!({"type": "reset"})).await;
    let (reset, _) = frame_where(&mut ws, |h| h["view"]["origin"] == first["view"]["origin"]).await;
    assert!(reset["epoch"].as_u64() > still["epoch"].as_u64());
    viewer.shutdown().await.unwrap();
}
