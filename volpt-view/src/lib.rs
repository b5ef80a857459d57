//! `volpt view`: an interactive viewer served as a web page, so that it works the same on a
//! workstation and on a laptop looking at a GPU server through `ssh -L`.
//!
//! - [`render`]: the one render thread, owner of the backend and the accumulation film.
//! - [`protocol`]: the WebSocket messages.
//! - [`encode`]: tone mapping, JPEG, PNG and OpenEXR.
//! - this module: the HTTP and WebSocket server (axum on tokio), its access checks, and a
//!   connection's task with its flow control (at most two unacknowledged frames).
//!
//! Security: a loopback bind serves requests whose `Host` is a loopback name (no DNS rebinding)
//! and WebSockets whose `Origin`, if any, is the page's own; any other bind needs the random token
//! printed in the URL on every request. Every input from the network is parsed into typed values
//! with errors; none panics.

pub mod encode;
pub mod protocol;
pub mod render;
pub mod tev;

use std::collections::VecDeque;
use std::net::SocketAddr;
use std::sync::atomic::Ordering;
use std::sync::Arc;

use axum::extract::ws::{CloseFrame, Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Query, Request, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::serve::ListenerExt;
use axum::Router;
use serde::Deserialize;
use tokio::sync::{broadcast, mpsc, watch};
use volpt::{BackendOptions, Scene};

use protocol::{
    ClientMessage, Hello, ImageFormat, ServerMessage, MAX_IN_FLIGHT, MAX_MESSAGE_BYTES,
};
use render::{Command, Commands, Shared};

/// The page: HTML, CSS and JavaScript in one file, embedded in the binary.
const PAGE: &str = include_str!("page.html");

#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    #[error(transparent)]
    Volpt(#[from] volpt::Error),
    #[error("{0}")]
    Encode(String),
    #[error("binding {addr}: {source}")]
    Bind {
        addr: SocketAddr,
        source: std::io::Error,
    },
    #[error("{0}")]
    Io(#[from] std::io::Error),
    #[error("the renderer is busy: message dropped, send fewer")]
    Busy,
    #[error("the renderer has stopped")]
    Stopped,
    #[error("no random token: {0}")]
    Random(String),
}

/// What `volpt view` serves.
pub struct ViewOptions {
    pub bind: SocketAddr,
    pub backend: BackendOptions,
    /// Require the token on a loopback bind too: on a shared machine every user reaches its
    /// loopback ports. (Any other bind always requires it.)
    pub token: bool,
    /// A tev viewer (`HOST:PORT`) to stream the linear image to as well ([`tev`]).
    pub tev: Option<String>,
}

/// What every connection's task shares.
struct AppState {
    shared: Arc<Shared>,
    commands: Commands,
    hello: Hello,
    /// Required on every request where the bind is not loopback.
    token: Option<String>,
    loopback: bool,
    shutdown: watch::Receiver<bool>,
}

/// A running viewer: its address and URL, and how to stop it.
pub struct Viewer {
    addr: SocketAddr,
    url: String,
    token: Option<String>,
    shutdown: watch::Sender<bool>,
    commands: Commands,
    shared: Arc<Shared>,
    server: tokio::task::JoinHandle<Result<(), std::io::Error>>,
    render: Option<std::thread::JoinHandle<()>>,
}

impl Viewer {
    /// Opens the backend on the render thread, binds `options.bind` and serves. Returns once the
    /// server accepts connections; errors (no GPU, address in use) come back here.
    pub async fn start(scene: Scene, options: ViewOptions) -> Result<Viewer, ViewError> {
        let (frames, _) = watch::channel(None);
        let (notices, _) = broadcast::channel(16);
        let shared = Arc::new(Shared {
            frames,
            notices,
            clients: Default::default(),
        });
        let (thread, commands, ready) = render::spawn(scene, options.backend, shared.clone());
        let hello = ready.await.map_err(|_| ViewError::Stopped)??;
        let loopback = options.bind.ip().is_loopback();
        let token = if loopback && !options.token {
            None
        } else {
            Some(random_token()?)
        };
        let listener = tokio::net::TcpListener::bind(options.bind)
            .await
            .map_err(|source| ViewError::Bind {
                addr: options.bind,
                source,
            })?;
        let addr = listener.local_addr()?;
        let (shutdown, shutdown_rx) = watch::channel(false);
        let scene_name = hello.scene.clone();
        let state = Arc::new(AppState {
            shared: shared.clone(),
            commands: commands.clone(),
            hello,
            token: token.clone(),
            loopback,
            shutdown: shutdown_rx.clone(),
        });
        let app = Router::new()
            .route("/", get(page))
            .route("/ws", get(ws))
            .route("/snapshot.exr", get(snapshot_exr))
            .route("/snapshot.png", get(snapshot_png))
            .layer(axum::middleware::from_fn_with_state(
                state.clone(),
                authorize,
            ))
            .with_state(state);
        if let Some(addr) = options.tev {
            let name = format!("volpt view: {scene_name}");
            tokio::spawn(tev::stream(
                addr,
                name,
                shared.clone(),
                commands.clone(),
                shutdown_rx.clone(),
            ));
        }
        let mut stop = shutdown_rx;
        let server = tokio::spawn(async move {
            // Frames and replies go out at once (TCP_NODELAY), as browsers send their messages:
            // with Nagle's algorithm a message's last segment waits for the peer's delayed ACK
            // (40 ms on Linux) whenever an earlier one is unacknowledged.
            let listener = listener.tap_io(|tcp| {
                if let Err(e) = tcp.set_nodelay(true) {
                    tracing::debug!("TCP_NODELAY: {e}");
                }
            });
            axum::serve(listener, app)
                .with_graceful_shutdown(async move {
                    let _ = stop.wait_for(|s| *s).await;
                })
                .await
        });
        let url = match &token {
            Some(t) => format!("http://{addr}/?token={t}"),
            None => format!("http://{addr}/"),
        };
        Ok(Viewer {
            addr,
            url,
            token,
            shutdown,
            commands,
            shared,
            server,
            render: Some(thread),
        })
    }

    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's address, with the token where one is needed.
    pub fn url(&self) -> &str {
        &self.url
    }

    pub fn token(&self) -> Option<&str> {
        self.token.as_deref()
    }

    /// Connections open now.
    pub fn clients(&self) -> usize {
        self.shared.clients.load(Ordering::SeqCst)
    }

    /// Closes every connection, stops the server and the render thread (after its batch in
    /// flight), and waits for both.
    pub async fn shutdown(mut self) -> Result<(), ViewError> {
        let _ = self.shutdown.send(true);
        // A full queue drains within a batch: retry until the command is in or the thread gone.
        while let Err(ViewError::Busy) = self.commands.send(Command::Shutdown) {
            tokio::time::sleep(std::time::Duration::from_millis(10)).await;
        }
        let served = (&mut self.server).await;
        if let Some(thread) = self.render.take() {
            tokio::task::spawn_blocking(move || thread.join())
                .await
                .ok();
        }
        match served {
            Ok(result) => Ok(result?),
            Err(e) => Err(ViewError::Encode(format!("server task: {e}"))),
        }
    }
}

/// Serves until Ctrl-C: prints the URL, then shuts down cleanly.
pub fn serve(scene: Scene, options: ViewOptions) -> Result<(), ViewError> {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    runtime.block_on(async move {
        let viewer = Viewer::start(scene, options).await?;
        println!("volpt view: open {}", viewer.url());
        if !viewer.local_addr().ip().is_loopback() {
            println!(
                "(served beyond this machine: the token in the URL is required; from a laptop, \
                 `ssh -L {0}:localhost:{0} HOST` and a loopback bind are the safer way)",
                viewer.local_addr().port()
            );
        }
        tokio::signal::ctrl_c().await?;
        eprintln!("volpt view: stopping");
        viewer.shutdown().await
    })
}

/// 128 random bits as hex.
fn random_token() -> Result<String, ViewError> {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes).map_err(|e| ViewError::Random(e.to_string()))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

#[derive(Deserialize)]
struct TokenQuery {
    token: Option<String>,
}

/// Equal strings in a time that does not depend on where they first differ.
fn same(a: &str, b: &str) -> bool {
    a.len() == b.len() && a.bytes().zip(b.bytes()).fold(0u8, |d, (x, y)| d | (x ^ y)) == 0
}

/// The hostname of a `Host` header value (`localhost:8080`, `[::1]:80`).
fn host_name(host: &str) -> &str {
    if let Some(rest) = host.strip_prefix('[') {
        return rest.split(']').next().unwrap_or("");
    }
    host.rsplit_once(':').map_or(host, |(name, _)| name)
}

/// The access check of every request (see the crate's doc).
async fn authorize(
    State(state): State<Arc<AppState>>,
    Query(query): Query<TokenQuery>,
    request: Request,
    next: Next,
) -> Response {
    let headers = request.headers();
    if let Some(token) = &state.token {
        if !query.token.as_deref().is_some_and(|t| same(t, token)) {
            return (StatusCode::FORBIDDEN, "a missing or wrong token\n").into_response();
        }
    } else {
        let host = headers
            .get(header::HOST)
            .and_then(|h| h.to_str().ok())
            .unwrap_or("");
        let name = host_name(host);
        let loopback_name = name.eq_ignore_ascii_case("localhost")
            || name
                .parse::<std::net::IpAddr>()
                .is_ok_and(|ip| ip.is_loopback());
        if state.loopback && !loopback_name {
            return (
                StatusCode::FORBIDDEN,
                "this viewer serves loopback addresses only (Host)\n",
            )
                .into_response();
        }
    }
    // A page of another site may open a WebSocket to a loopback port: refuse foreign origins.
    if let Some(origin) = headers.get(header::ORIGIN).and_then(|o| o.to_str().ok()) {
        let host = headers
            .get(header::HOST)
            .and_then(|h| h.to_str().ok())
            .unwrap_or("");
        let own = origin
            .strip_prefix("http://")
            .or_else(|| origin.strip_prefix("https://"))
            .is_some_and(|o| o.eq_ignore_ascii_case(host));
        if !own {
            return (StatusCode::FORBIDDEN, "a foreign Origin\n").into_response();
        }
    }
    next.run(request).await
}

async fn page() -> impl IntoResponse {
    (
        [
            (header::CONTENT_TYPE, "text/html; charset=utf-8"),
            (header::CACHE_CONTROL, "no-store"),
        ],
        PAGE,
    )
}

/// The latest frame; `None` before the first.
fn latest(state: &AppState) -> Option<Arc<render::Frame>> {
    state.shared.frames.borrow().clone()
}

fn no_frame() -> Response {
    (StatusCode::SERVICE_UNAVAILABLE, "no frame yet\n").into_response()
}

fn download(bytes: Vec<u8>, mime: &'static str, name: &'static str) -> Response {
    let mut headers = HeaderMap::new();
    headers.insert(header::CONTENT_TYPE, HeaderValue::from_static(mime));
    headers.insert(header::CONTENT_DISPOSITION, HeaderValue::from_static(name));
    (headers, bytes).into_response()
}

/// The latest frame's linear image as OpenEXR.
async fn snapshot_exr(State(state): State<Arc<AppState>>) -> Response {
    let Some(frame) = latest(&state) else {
        return no_frame();
    };
    match tokio::task::spawn_blocking(move || encode::exr(&frame.linear)).await {
        Ok(Ok(bytes)) => download(
            bytes,
            "image/x-exr",
            "attachment; filename=\"volpt-view.exr\"",
        ),
        Ok(Err(e)) => (StatusCode::INTERNAL_SERVER_ERROR, e.to_string()).into_response(),
        Err(e) => (StatusCode::INTERNAL_SERVER_ERROR, e.to_string()).into_response(),
    }
}

/// The latest frame as shown (exposure, sRGB) as PNG.
async fn snapshot_png(State(state): State<Arc<AppState>>) -> Response {
    let Some(frame) = latest(&state) else {
        return no_frame();
    };
    let png = tokio::task::spawn_blocking(move || frame.png().map(<[u8]>::to_vec)).await;
    match png {
        Ok(Ok(bytes)) => download(
            bytes,
            "image/png",
            "attachment; filename=\"volpt-view.png\"",
        ),
        Ok(Err(e)) => (StatusCode::INTERNAL_SERVER_ERROR, e.to_string()).into_response(),
        Err(e) => (StatusCode::INTERNAL_SERVER_ERROR, e.to_string()).into_response(),
    }
}

async fn ws(State(state): State<Arc<AppState>>, upgrade: WebSocketUpgrade) -> Response {
    upgrade
        .max_message_size(MAX_MESSAGE_BYTES)
        .max_frame_size(MAX_MESSAGE_BYTES)
        .on_upgrade(move |socket| connection(socket, state))
}

/// Counts a connection while it lives: the render thread renders only for someone.
struct ClientGuard(Arc<Shared>);

impl ClientGuard {
    fn new(shared: &Arc<Shared>) -> Self {
        shared.clients.fetch_add(1, Ordering::SeqCst);
        Self(shared.clone())
    }
}

impl Drop for ClientGuard {
    fn drop(&mut self) {
        self.0.clients.fetch_sub(1, Ordering::SeqCst);
    }
}

/// One page's connection: forwards its messages to the render thread and the latest frame to it,
/// with at most [`MAX_IN_FLIGHT`] frames unacknowledged. Ends when the page goes, on an oversize
/// or unreadable message, or at shutdown; what it held (its count, its subscriptions) goes with it.
async fn connection(mut socket: WebSocket, state: Arc<AppState>) {
    let _guard = ClientGuard::new(&state.shared);
    let _ = state.commands.send(Command::Wake);
    let hello = ServerMessage::Hello(&state.hello).to_json();
    if socket.send(Message::Text(hello.into())).await.is_err() {
        return;
    }
    let mut frames = state.shared.frames.subscribe();
    let mut notices = state.shared.notices.subscribe();
    let mut shutdown = state.shutdown.clone();
    let (outbox, mut replies) = mpsc::channel::<String>(16);
    let mut in_flight: VecDeque<u64> = VecDeque::new();
    let mut format = ImageFormat::Jpeg;
    let mut last_sent = 0u64;
    // A frame is waiting to be sent once the in-flight window allows (the first: the current one).
    let mut pending = true;
    loop {
        if pending && in_flight.len() < MAX_IN_FLIGHT {
            pending = false;
            let frame = frames.borrow_and_update().clone();
            if let Some(frame) = frame.filter(|f| f.header.frame != last_sent) {
                let message = frame.image(format).map(|image| {
                    let mut header = frame.header.clone();
                    header.format = format;
                    protocol::frame_message(&header, image)
                });
                match message {
                    Ok(bytes) => {
                        if socket.send(Message::Binary(bytes.into())).await.is_err() {
                            return;
                        }
                        last_sent = frame.header.frame;
                        in_flight.push_back(last_sent);
                    }
                    Err(e) => {
                        let text = ServerMessage::Error {
                            message: e.to_string(),
                        };
                        if socket
                            .send(Message::Text(text.to_json().into()))
                            .await
                            .is_err()
                        {
                            return;
                        }
                    }
                }
            }
        }
        tokio::select! {
            changed = frames.changed() => {
                if changed.is_err() {
                    return;
                }
                pending = true;
            }
            notice = notices.recv() => {
                if let Ok(text) = notice {
                    if socket.send(Message::Text(text.into())).await.is_err() {
                        return;
                    }
                }
            }
            Some(text) = replies.recv() => {
                if socket.send(Message::Text(text.into())).await.is_err() {
                    return;
                }
            }
            _ = shutdown.changed() => {
                let _ = socket.send(Message::Close(Some(CloseFrame {
                    code: 1001,
                    reason: "the server is stopping".into(),
                }))).await;
                return;
            }
            message = socket.recv() => {
                let text = match message {
                    None | Some(Ok(Message::Close(_))) => return,
                    Some(Err(e)) => {
                        // Oversize or not WebSocket: say why (1009: too big) and end.
                        tracing::debug!("a client's connection failed: {e}");
                        let _ = socket.send(Message::Close(Some(CloseFrame {
                            code: 1009,
                            reason: "message too big or malformed".into(),
                        }))).await;
                        return;
                    }
                    Some(Ok(Message::Text(text))) => text,
                    Some(Ok(Message::Binary(_))) => {
                        refuse(&outbox, "binary messages are not accepted; send JSON text".into());
                        continue;
                    }
                    Some(Ok(_)) => continue, // ping and pong: the library answers pings
                };
                match handle(text.as_str(), &state, &outbox, &mut in_flight, &mut format) {
                    Ok(Some(Handled::Resend)) => {
                        pending = true;
                        last_sent = 0;
                    }
                    Ok(Some(Handled::Acked)) => pending = true,
                    Ok(None) => {}
                    Err(message) => refuse(&outbox, message),
                }
            }
        }
    }
}

/// What a message changed for its own connection.
enum Handled {
    /// An acknowledgement opened the window.
    Acked,
    /// The format changed: send the current frame again in it.
    Resend,
}

fn refuse(outbox: &mpsc::Sender<String>, message: String) {
    let _ = outbox.try_send(ServerMessage::Error { message }.to_json());
}

/// Applies one text message; `Err` is the error reply (and nothing changed).
fn handle(
    text: &str,
    state: &AppState,
    outbox: &mpsc::Sender<String>,
    in_flight: &mut VecDeque<u64>,
    format: &mut ImageFormat,
) -> Result<Option<Handled>, String> {
    let message = ClientMessage::parse(text).map_err(|e| e.to_string())?;
    let send = |command| state.commands.send(command).map_err(|e| e.to_string());
    match message {
        ClientMessage::Ack { frame } => {
            let Some(i) = in_flight.iter().position(|&f| f == frame) else {
                return Err(format!("ack: frame {frame} is not in flight"));
            };
            // Frames arrive in order: an ack covers the frames sent before it too.
            in_flight.drain(..=i);
            return Ok(Some(Handled::Acked));
        }
        ClientMessage::Format { format: f } => {
            *format = f;
            return Ok(Some(Handled::Resend));
        }
        ClientMessage::Camera {
            origin,
            target,
            fov,
            interactive,
        } => send(Command::Camera {
            origin,
            target,
            fov,
            interactive,
            reply: outbox.clone(),
        })?,
        ClientMessage::Set { key, value } => {
            let value = protocol::param_value(&key, &value).map_err(|e| e.to_string())?;
            send(Command::Set {
                key,
                value,
                reply: outbox.clone(),
            })?
        }
        ClientMessage::Exposure { value } => send(Command::Exposure(value))?,
        ClientMessage::Reset => send(Command::Reset)?,
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn host_names_and_tokens() {
        assert_eq!(host_name("localhost:8080"), "localhost");
        assert_eq!(host_name("[::1]:80"), "::1");
        assert_eq!(host_name("127.0.0.1"), "127.0.0.1");
        assert!(same("abc", "abc"));
        assert!(!same("abc", "abd"));
        assert!(!same("abc", "ab"));
        let t = random_token().unwrap();
        assert_eq!(t.len(), 32);
        assert_ne!(t, random_token().unwrap());
    }
}
