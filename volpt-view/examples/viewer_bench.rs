//! A scripted viewer client that measures `volpt view` end to end: render + tone map + encode +
//! send, as a page sees it. Used by `bench/device/viewer.sh`.
//!
//! Usage: viewer_bench WS_URL [SECONDS]
//!
//! Three phases, each timed on this side of the socket, every frame acknowledged at once:
//! 1. latency: ten still camera moves, one at a time: the time from sending the move to the first
//!    frame of the new epoch (one sample at full resolution);
//! 2. still: frames/s of the progressive refinement of one view for SECONDS (default 3);
//! 3. orbit: camera moves at 60 Hz (interactive, as a drag sends them) for SECONDS: frames/s of
//!    frames showing a move, the time from a move to the frame showing it, and the resolution.
//!
//! Between 1 and 2, the view of the first move is shown again: its first frame of one whole sample
//! (the first frame, unless paths were in flight at its deadline) must equal the first time's
//! byte for byte (`repeat_identical`), as a render of a scene whose camera went
//! elsewhere and came back, its grids kept on the GPU in between, must.
//!
//! Prints one JSON object.
//!
//! Usage: viewer_bench WS_URL --snapshot FILE
//!
//! The accumulation instead: a drag away from the initial view and a still move back, then the
//! linear image (`/snapshot.exr`) once the still view has all its samples, written to FILE
//! (bench/device/viewer.sh compares the GPU's with the CPU's); prints the last frame's header and
//! how many of the still view's frames had paths in flight.

use std::time::{Duration, Instant};

use futures_util::{SinkExt, StreamExt};
use serde_json::{json, Value};
use tokio_tungstenite::tungstenite::Message;
use volpt_view::protocol::split_frame;

type Ws =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

fn vec3(v: &Value) -> [f64; 3] {
    let a = |i: usize| v[i].as_f64().unwrap_or(0.0);
    [a(0), a(1), a(2)]
}

/// `origin` turned by `angle` radians around the axis `up` through `target` (Rodrigues).
fn orbit(origin: [f64; 3], target: [f64; 3], up: [f64; 3], angle: f64) -> [f64; 3] {
    let n = (up[0] * up[0] + up[1] * up[1] + up[2] * up[2]).sqrt();
    let k = up.map(|c| c / n);
    let v = [0, 1, 2].map(|i| origin[i] - target[i]);
    let kv = [
        k[1] * v[2] - k[2] * v[1],
        k[2] * v[0] - k[0] * v[2],
        k[0] * v[1] - k[1] * v[0],
    ];
    let kdv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
    let (s, c) = angle.sin_cos();
    [0, 1, 2].map(|i| target[i] + v[i] * c + kv[i] * s + k[i] * kdv * (1.0 - c))
}

async fn send(ws: &mut Ws, message: Value) {
    ws.send(Message::Text(message.to_string().into()))
        .await
        .expect("sending");
}

/// The next frame (acknowledged), or `None` at `deadline`: its header, its image's size and a hash
/// of the image.
async fn next_frame(ws: &mut Ws, deadline: Instant) -> Option<(Value, usize, u64)> {
    loop {
        let message = tokio::time::timeout_at(deadline.into(), ws.next())
            .await
            .ok()??;
        match message.ok()? {
            Message::Binary(b) => {
                let (header, image) = split_frame(&b)?;
                send(ws, json!({"type": "ack", "frame": header["frame"]})).await;
                let mut hash = std::hash::DefaultHasher::new();
                std::hash::Hash::hash(image, &mut hash);
                return Some((header, image.len(), std::hash::Hasher::finish(&hash)));
            }
            Message::Text(t) => eprintln!("viewer_bench: server says {t}"),
            Message::Close(_) => return None,
            _ => {}
        }
    }
}

/// The image hash of epoch `epoch`'s first frame of one whole sample: `first` (that epoch's first
/// frame) if it is one, else the next that is. A frame with paths in flight (a multi-kernel
/// strategy's, stopped at its deadline) shows those that had ended by then, which depends on time.
async fn first_sample(ws: &mut Ws, epoch: u64, first: &(Value, u64)) -> Option<u64> {
    if first.0["spp"].as_u64() >= Some(1) {
        return Some(first.1);
    }
    let deadline = Instant::now() + Duration::from_secs(60);
    while let Some((h, _, image)) = next_frame(ws, deadline).await {
        if h["epoch"].as_u64() == Some(epoch) && h["spp"].as_u64() >= Some(1) {
            return Some(image);
        }
    }
    None
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    v.sort_by(|a, b| a.total_cmp(b));
    (!v.is_empty()).then(|| v[v.len() / 2])
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// The accumulation mode: a drag away, a still move back to the initial view, then its linear
/// image once it has all its samples, written to `file`. Prints the last frame's header and how
/// many frames of the still view showed paths in flight.
async fn snapshot(ws: &mut Ws, url: &str, hello: &Value, file: &str) {
    let initial = &hello["initial"];
    let (origin, target, up) = (
        vec3(&initial["origin"]),
        vec3(&initial["target"]),
        vec3(&initial["up"]),
    );
    let far = Instant::now() + Duration::from_secs(60);
    next_frame(ws, far).await.expect("a first frame");
    let away = orbit(origin, target, up, 0.3);
    let drag = json!({"type": "camera", "origin": away, "target": target, "interactive": true});
    send(ws, drag).await;
    while let Some((h, _, _)) = next_frame(ws, far).await {
        if h["interactive"] == true {
            break;
        }
    }
    send(
        ws,
        json!({"type": "camera", "origin": initial["origin"], "target": initial["target"]}),
    )
    .await;
    let mut in_flight = 0u32;
    let last = loop {
        let (h, _, _) = next_frame(ws, far).await.expect("the still view's frames");
        in_flight += u32::from(h["spp_in_flight"].as_u64() > Some(0));
        let still = h["interactive"] == false && h["view"]["origin"] == initial["origin"];
        if still && h["spp"] == h["spp_target"] {
            break h;
        }
    };
    // The page's server, by HTTP: ws://HOST:PORT/ws -> HOST:PORT.
    let host = url
        .trim_start_matches("ws://")
        .split('/')
        .next()
        .expect("ws://HOST:PORT/ws");
    let mut stream = std::net::TcpStream::connect(host).expect("connecting for the snapshot");
    use std::io::{Read, Write};
    write!(
        stream,
        "GET /snapshot.exr HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n"
    )
    .expect("asking for the snapshot");
    let mut response = Vec::new();
    stream
        .read_to_end(&mut response)
        .expect("reading the snapshot");
    assert!(
        response.starts_with(b"HTTP/1.1 200"),
        "snapshot refused: {}",
        String::from_utf8_lossy(&response[..response.len().min(200)])
    );
    let body = response
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("an HTTP response")
        + 4;
    std::fs::write(file, &response[body..]).expect("writing the snapshot");
    println!(
        "{}",
        json!({"last": last, "still_frames_with_paths_in_flight": in_flight})
    );
}

#[tokio::main(flavor = "current_thread")]
async fn main() {
    let mut args = std::env::args().skip(1);
    let url = args
        .next()
        .expect("usage: viewer_bench WS_URL [SECONDS | --snapshot FILE]");
    let mode = args.next();
    // Messages go out at once, as a browser's do (TCP_NODELAY): with Nagle's algorithm, a move
    // sent right after an ack waits for the server's delayed ACK of that ack (40 ms on Linux)
    // whenever the server has nothing to send: the frames it would send wait for the move.
    let (mut ws, _) = tokio_tungstenite::connect_async_with_config(&url, None, true)
        .await
        .expect("connecting");
    let hello: Value = match ws.next().await {
        Some(Ok(Message::Text(t))) => serde_json::from_str(&t).expect("hello"),
        other => panic!("expected hello, got {other:?}"),
    };
    if mode.as_deref() == Some("--snapshot") {
        let file = args.next().expect("--snapshot FILE");
        return snapshot(&mut ws, &url, &hello, &file).await;
    }
    let seconds: f64 = mode.map_or(3.0, |s| s.parse().expect("SECONDS"));
    let initial = &hello["initial"];
    let (origin, target, up) = (
        vec3(&initial["origin"]),
        vec3(&initial["target"]),
        vec3(&initial["up"]),
    );
    // Refinement must not stop within a phase.
    send(
        &mut ws,
        json!({"type": "set", "key": "spp", "value": 1 << 20}),
    )
    .await;
    let far = Instant::now() + Duration::from_secs(120);
    let (first, _, _) = next_frame(&mut ws, far).await.expect("a first frame");
    let mut epoch = first["epoch"].as_u64().unwrap_or(0);

    // 1. Latency of a still move: send, wait for the new epoch's first frame.
    let mut latency = Vec::new();
    let mut first_frames = Vec::new();
    let mut reference = None;
    for i in 0..10 {
        let o = orbit(origin, target, up, 0.05 * f64::from(i + 1));
        let sent = Instant::now();
        send(
            &mut ws,
            json!({"type": "camera", "origin": o, "target": target}),
        )
        .await;
        while let Some((h, _, image)) = next_frame(&mut ws, sent + Duration::from_secs(60)).await {
            if h["epoch"].as_u64() > Some(epoch) {
                epoch = h["epoch"].as_u64().unwrap_or(epoch);
                latency.push(sent.elapsed().as_secs_f64() * 1e3);
                first_frames.push((h, image));
                break;
            }
        }
        if i == 0 {
            reference = first_sample(&mut ws, epoch, &first_frames[0]).await;
        }
    }
    // The first move's view again: the same image.
    let sent = Instant::now();
    let o = orbit(origin, target, up, 0.05);
    send(
        &mut ws,
        json!({"type": "camera", "origin": o, "target": target}),
    )
    .await;
    let mut repeat_identical = None;
    while let Some((h, _, image)) = next_frame(&mut ws, sent + Duration::from_secs(60)).await {
        if h["epoch"].as_u64() > Some(epoch) {
            epoch = h["epoch"].as_u64().unwrap_or(epoch);
            let shown = first_sample(&mut ws, epoch, &(h, image)).await;
            repeat_identical = reference.zip(shown).map(|(a, b)| a == b);
            break;
        }
    }

    // 2. Still: the refinement's frame rate.
    let started = Instant::now();
    let mut still_frames = 0u32;
    let mut last_still = Value::Null;
    while let Some((h, _, _)) =
        next_frame(&mut ws, started + Duration::from_secs_f64(seconds)).await
    {
        if h["epoch"].as_u64() == Some(epoch) {
            still_frames += 1;
            last_still = h;
        }
    }
    let still_s = started.elapsed().as_secs_f64();

    // 3. Orbit: interactive moves at 60 Hz, as a drag sends them.
    let started = Instant::now();
    let end = started + Duration::from_secs_f64(seconds);
    let mut tick = tokio::time::interval(Duration::from_micros(16_667));
    let mut sent: Vec<([f64; 3], Instant)> = Vec::new();
    // The frames' numbers: a gap is frames the server made that this client never got.
    let mut ids: Vec<u64> = Vec::new();
    let (mut frames, mut move_latency, mut widths) = (0u32, Vec::new(), Vec::new());
    let (mut setup, mut render, mut tonemap, mut encode, mut bytes) =
        (vec![], vec![], vec![], vec![], vec![]);
    let mut angle = 0.6;
    loop {
        tokio::select! {
            _ = tick.tick() => {
                if Instant::now() >= end { break; }
                angle += 0.02;
                let o = orbit(origin, target, up, angle);
                sent.push((o, Instant::now()));
                send(&mut ws, json!({"type": "camera", "origin": o, "target": target,
                                     "interactive": true})).await;
            }
            frame = next_frame(&mut ws, end) => {
                let Some((h, size, _)) = frame else { break };
                if h["interactive"] != true { continue; }
                frames += 1;
                ids.push(h["frame"].as_u64().unwrap_or(0));
                let shown = vec3(&h["view"]["origin"]);
                // The move this frame shows: the server echoes the origin as f32.
                if let Some((_, at)) = sent.iter().rev().find(|(o, _)| {
                    (0..3).all(|i| (o[i] - shown[i]).abs() <= 1e-5 * (1.0 + o[i].abs()))
                }) {
                    move_latency.push(at.elapsed().as_secs_f64() * 1e3);
                }
                widths.push(format!("{}x{}", h["width"], h["height"]));
                setup.push(h["setup_ms"].as_f64().unwrap_or(0.0));
                render.push(h["render_ms"].as_f64().unwrap_or(0.0));
                tonemap.push(h["tonemap_ms"].as_f64().unwrap_or(0.0));
                encode.push(h["encode_ms"].as_f64().unwrap_or(0.0));
                bytes.push(size as f64);
            }
        }
    }
    let orbit_s = started.elapsed().as_secs_f64();
    send(
        &mut ws,
        json!({"type": "camera", "origin": origin, "target": target}),
    )
    .await;
    widths.sort();
    let common = widths
        .chunk_by(|a, b| a == b)
        .max_by_key(|c| c.len())
        .map(|c| c[0].clone());
    let first_render: Vec<f64> = first_frames
        .iter()
        .map(|(h, _)| h["render_ms"].as_f64().unwrap_or(0.0))
        .collect();
    let first_setup: Vec<f64> = first_frames
        .iter()
        .map(|(h, _)| h["setup_ms"].as_f64().unwrap_or(0.0))
        .collect();
    let first_encode: Vec<f64> = first_frames
        .iter()
        .map(|(h, _)| {
            h["tonemap_ms"].as_f64().unwrap_or(0.0) + h["encode_ms"].as_f64().unwrap_or(0.0)
        })
        .collect();
    let report = json!({
        "backend": hello["backend"], "device": hello["device"], "strategy": hello["strategy"],
        "math": hello["math"], "width": hello["width"], "height": hello["height"],
        "repeat_identical": repeat_identical,
        "still_move_to_frame_ms_median": median(latency.clone()),
        "still_move_to_frame_ms_all": latency,
        "still_first_frame_setup_ms_median": median(first_setup),
        "still_first_frame_render_ms_median": median(first_render),
        "still_first_frame_tonemap_encode_ms_median": median(first_encode),
        "still_frames_per_s": f64::from(still_frames) / still_s,
        "still_spp_after": last_still["spp"], "still_paths_per_s": last_still["paths_per_s"],
        "orbit_frames_per_s": f64::from(frames) / orbit_s,
        "orbit_moves_sent": sent.len(),
        "orbit_frames_made_not_received": match (ids.first(), ids.last()) {
            (Some(first), Some(last)) => (last - first + 1).saturating_sub(ids.len() as u64),
            _ => 0,
        },
        "orbit_move_to_frame_ms_median": median(move_latency),
        "orbit_resolution": common,
        "orbit_setup_ms_mean": mean(&setup), "orbit_render_ms_mean": mean(&render), "orbit_tonemap_ms_mean": mean(&tonemap),
        "orbit_encode_ms_mean": mean(&encode), "orbit_jpeg_bytes_mean": mean(&bytes),
    });
    println!("{report}");
}
