//! The render thread: it alone owns the backend, the scene and the accumulation film. It refines
//! the current view progressively and starts a new accumulation (a new epoch) when the view or a
//! parameter changes. Frames go out through a `watch` channel, which keeps only the latest:
//! a client that falls behind skips frames instead of queueing them.
//!
//! A frame's render stops at its deadline with paths in flight where the GPU's strategy keeps
//! them (the multi-kernel ones); the next frames of the view continue them, so that a frame need
//! not wait for its longest path, and a move discards them.
//!
//! Invariants: `film` holds samples `0..done` of `scene` as it is now, at the scene's current
//! resolution, and of the range `in_flight` (if any) the paths that have ended; every published
//! frame's `epoch` names the scene state it was rendered from.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender, TrySendError};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use tokio::sync::{broadcast, mpsc, oneshot, watch};
use volpt::{Backend, BackendOptions, Film, Image, ParamValue, Scene};

use crate::encode;
use crate::protocol::{
    FrameHeader, Hello, ImageFormat, MaterialParams, Params, ServerMessage, View,
};
use crate::ViewError;

/// A client's queue of text messages (error replies), bounded: a reply that does not fit is
/// dropped rather than block the render thread.
pub type Outbox = mpsc::Sender<String>;

/// What clients ask of the render thread.
pub enum Command {
    Camera {
        origin: [f32; 3],
        target: [f32; 3],
        fov: Option<f32>,
        interactive: bool,
        reply: Outbox,
    },
    Set {
        key: String,
        value: ParamValue,
        reply: Outbox,
    },
    Exposure(f32),
    Reset,
    /// A client connected: render if the thread was idle for want of clients.
    Wake,
    Shutdown,
}

/// Commands queued at most; a client that sends faster than the renderer drains gets "busy".
const QUEUE: usize = 1024;

/// The sending side of the render thread's queue.
#[derive(Clone)]
pub struct Commands(SyncSender<Command>);

impl Commands {
    pub fn send(&self, command: Command) -> Result<(), ViewError> {
        self.0.try_send(command).map_err(|e| match e {
            TrySendError::Full(_) => ViewError::Busy,
            TrySendError::Disconnected(_) => ViewError::Stopped,
        })
    }
}

/// One rendered, tone-mapped and encoded image.
pub struct Frame {
    pub header: FrameHeader,
    /// The linear image (EXR snapshots).
    pub linear: Image,
    /// 8-bit sRGB after exposure (PNG snapshots and frames).
    pub rgb: Vec<u8>,
    pub jpeg: Vec<u8>,
    png: OnceLock<Result<Vec<u8>, String>>,
}

impl Frame {
    /// The frame as PNG, encoded once on first request.
    pub fn png(&self) -> Result<&[u8], ViewError> {
        let (w, h) = (self.header.width, self.header.height);
        self.png
            .get_or_init(|| encode::png(&self.rgb, w, h).map_err(|e| e.to_string()))
            .as_deref()
            .map_err(|e| ViewError::Encode(e.clone()))
    }

    pub fn image(&self, format: ImageFormat) -> Result<&[u8], ViewError> {
        match format {
            ImageFormat::Jpeg => Ok(&self.jpeg),
            ImageFormat::Png => self.png(),
        }
    }
}

/// What the render thread and the connections share.
pub struct Shared {
    pub frames: watch::Sender<Option<Arc<Frame>>>,
    /// Server-wide notices (a failed render, auto's choice), as `error` or `notice` JSON.
    pub notices: broadcast::Sender<String>,
    pub clients: AtomicUsize,
}

/// While the user drags, the renderer aims at this frame time (30 frames/s with a margin).
const INTERACTIVE_BUDGET: f64 = 0.030;
/// While the user drags, a frame's render stops here with paths in flight where the GPU can
/// keep them: the rest of the frame time is for the tone mapping, the JPEG and the send.
const DRAG_RENDER_BUDGET: f64 = 0.6 * INTERACTIVE_BUDGET;
/// Reduced resolutions while dragging: the full one divided by these.
const SCALES: [f32; 9] = [1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0];
/// A drag whose last move is this old is over (a lost or never-sent release).
const STILL_AFTER: Duration = Duration::from_millis(300);
/// JPEG quality of frames.
const QUALITY: u8 = 85;

struct Renderer {
    scene: Scene,
    backend: Backend,
    film: Film,
    shared: Arc<Shared>,
    full: (u32, u32),
    view: View,
    initial: View,
    epoch: u64,
    done: u32,
    interactive: bool,
    last_move: Instant,
    epoch_started: Instant,
    epoch_render: Duration,
    epoch_paths: u64,
    /// Samples whose paths are in flight on the GPU: the next frames continue them.
    in_flight: Option<std::ops::Range<u32>>,
    /// Render time of the range being rendered so far, over its frames.
    range_render: Duration,
    exposure: f32,
    /// Index into [`SCALES`] used while dragging, adapted to the measured frame time.
    scale: usize,
    /// Seconds per pixel-sample of the latest render, to size the next batch.
    sample_time: Option<f64>,
    /// The latest frame needs tone mapping again (the exposure changed).
    retone: bool,
    /// When the render thread took its latest commands (a frame's setup time runs from there).
    commands_taken: Instant,
    next_frame: u64,
}

/// Starts the render thread: opens the backend there (a GPU context stays on its thread) and
/// answers with what the page is told on connection.
pub fn spawn(
    scene: Scene,
    options: BackendOptions,
    shared: Arc<Shared>,
) -> (
    std::thread::JoinHandle<()>,
    Commands,
    oneshot::Receiver<Result<Hello, ViewError>>,
) {
    let (tx, rx) = std::sync::mpsc::sync_channel(QUEUE);
    let (ready, ready_rx) = oneshot::channel();
    let thread = std::thread::Builder::new()
        .name("volpt-view render".into())
        .spawn(move || match Renderer::open(scene, &options, shared) {
            Ok((renderer, hello)) => {
                let _ = ready.send(Ok(hello));
                renderer.run(rx);
            }
            Err(e) => {
                let _ = ready.send(Err(e));
            }
        })
        .expect("spawning the render thread");
    (thread, Commands(tx), ready_rx)
}

impl Renderer {
    fn open(
        mut scene: Scene,
        options: &BackendOptions,
        shared: Arc<Shared>,
    ) -> Result<(Self, Hello), ViewError> {
        let backend = Backend::open(options)?;
        // The viewer's one backend reads the grids in place (no copy of the description).
        backend.adopt(&mut scene);
        let view = initial_view(&mut scene)?;
        let full = scene.resolution();
        let hello = Hello {
            scene: scene.source().to_owned(),
            backend: format!("{:?}", backend.kind()).to_lowercase(),
            device: backend.device_name(),
            strategy: backend.strategy().map(|s| s.to_string()),
            math: backend.math().map(|m| m.name().to_owned()),
            width: full.0,
            height: full.1,
            initial: view,
            max_message_bytes: crate::protocol::MAX_MESSAGE_BYTES,
            max_in_flight: crate::protocol::MAX_IN_FLIGHT,
        };
        let now = Instant::now();
        let renderer = Self {
            film: scene.film(),
            scene,
            backend,
            shared,
            full,
            view,
            initial: view,
            epoch: 0,
            done: 0,
            interactive: false,
            last_move: now,
            epoch_started: now,
            epoch_render: Duration::ZERO,
            epoch_paths: 0,
            in_flight: None,
            range_render: Duration::ZERO,
            exposure: 0.0,
            scale: 2,
            sample_time: None,
            retone: false,
            commands_taken: now,
            next_frame: 0,
        };
        Ok((renderer, hello))
    }

    /// Samples per pixel this epoch refines to: one while dragging, else the scene's.
    fn cap(&self) -> u32 {
        if self.interactive {
            1
        } else {
            self.scene.spp()
        }
    }

    fn run(mut self, rx: Receiver<Command>) {
        loop {
            let clients = self.shared.clients.load(Ordering::SeqCst);
            let work = clients > 0 && (self.done < self.cap() || self.retone);
            let mut commands = Vec::new();
            // Block for a command only with nothing to render; a drag's end is a timeout.
            if !work {
                let first = if clients > 0 && self.interactive {
                    match rx.recv_timeout(STILL_AFTER.saturating_sub(self.last_move.elapsed())) {
                        Ok(c) => Some(c),
                        Err(RecvTimeoutError::Timeout) => None,
                        Err(RecvTimeoutError::Disconnected) => return,
                    }
                } else {
                    match rx.recv() {
                        Ok(c) => Some(c),
                        Err(_) => return,
                    }
                };
                commands.extend(first);
            }
            commands.extend(rx.try_iter());
            self.commands_taken = Instant::now();
            let mut restart = false;
            for command in superseded_moves_dropped(commands) {
                match command {
                    Command::Shutdown => return,
                    Command::Wake => {}
                    Command::Exposure(stops) => {
                        self.exposure = stops;
                        self.retone = true;
                    }
                    Command::Reset => {
                        self.apply_view(self.initial, None)
                            .unwrap_or_else(|e| tracing::error!("reset: {e}"));
                        self.interactive = false;
                        restart = true;
                    }
                    Command::Camera {
                        origin,
                        target,
                        fov,
                        interactive,
                        reply,
                    } => {
                        let view = View {
                            origin,
                            target,
                            ..self.view
                        };
                        match self.apply_view(view, fov) {
                            Ok(()) => {
                                self.interactive = interactive;
                                if interactive {
                                    self.last_move = Instant::now();
                                }
                                restart = true;
                            }
                            Err(e) => refuse(&reply, format!("camera: {e}")),
                        }
                    }
                    Command::Set { key, value, reply } => match self.scene.set(&key, value) {
                        // More samples per pixel continue the accumulation; anything else
                        // renders another image.
                        Ok(()) if key == "spp" => {}
                        Ok(()) => {
                            if key == "camera.fov" {
                                if let Ok(ParamValue::Float(f)) = self.scene.get(&key) {
                                    self.view.fov = f;
                                }
                            }
                            restart = true;
                        }
                        Err(e) => refuse(&reply, e.to_string()),
                    },
                }
            }
            if self.interactive && self.last_move.elapsed() >= STILL_AFTER {
                self.interactive = false;
                restart = true;
            }
            if restart {
                self.new_epoch();
            }
            if self.shared.clients.load(Ordering::SeqCst) == 0 {
                continue;
            }
            if self.done < self.cap() {
                self.render_batch();
            } else if self.retone && self.shown() > 0 {
                self.publish(Duration::ZERO, Duration::ZERO);
            }
            self.retone = false;
        }
    }

    /// Moves the camera to `view` (and `fov`); on a refusal the camera stays where it was.
    fn apply_view(&mut self, view: View, fov: Option<f32>) -> Result<(), volpt::Error> {
        let before = self.view;
        let mut set = |v: &View, fov: Option<f32>| -> Result<(), volpt::Error> {
            self.scene
                .set("camera.origin", ParamValue::Vec3(v.origin))?;
            self.scene
                .set("camera.target", ParamValue::Vec3(v.target))?;
            if let Some(fov) = fov {
                self.scene.set("camera.fov", ParamValue::Float(fov))?;
            }
            Ok(())
        };
        match set(&view, fov.or(Some(view.fov))) {
            Ok(()) => {
                self.view = View {
                    fov: fov.unwrap_or(view.fov),
                    ..view
                };
                Ok(())
            }
            Err(e) => {
                // The view before was accepted, so setting it again succeeds.
                let _ = set(&before, Some(before.fov));
                Err(e)
            }
        }
    }

    /// A new accumulation: at a reduced resolution while dragging, else the full one.
    fn new_epoch(&mut self) {
        self.epoch += 1;
        let (w, h) = self.full;
        let (w, h) = if self.interactive {
            let s = SCALES[self.scale];
            let reduce = |n: u32| ((n as f32 / s).round() as u32).max(1);
            (reduce(w), reduce(h))
        } else {
            (w, h)
        };
        if self.scene.resolution() != (w, h) {
            if let Err(e) = self.scene.set_resolution(w, h) {
                tracing::error!("resolution {w}x{h}: {e}");
            }
        }
        // The film of the same size is cleared rather than allocated anew: a new film's pages
        // are the kernel's zero pages, each faulted in when the first render's sums land there
        // (a drag starts an epoch at every frame).
        if (self.film.width, self.film.height) == self.scene.resolution() {
            self.film.sums.fill([0.0; 3]);
        } else {
            self.film = self.scene.film();
        }
        self.done = 0;
        // The old view's paths in flight are discarded (the GPU's, by the next render).
        self.in_flight = None;
        self.range_render = Duration::ZERO;
        self.epoch_started = Instant::now();
        self.epoch_render = Duration::ZERO;
        self.epoch_paths = 0;
    }

    /// Samples for the next frame and the time its render may take: one sample while dragging
    /// (within [`DRAG_RENDER_BUDGET`]) or for an epoch's first frame, then as many as fit a frame
    /// time that grows with the epoch's age (4 to 33 frames/s).
    fn batch(&self) -> (u32, f64) {
        let left = self.cap().saturating_sub(self.done);
        if self.interactive {
            return (left.min(1), DRAG_RENDER_BUDGET);
        }
        let budget = (0.25 * self.epoch_started.elapsed().as_secs_f64()).clamp(0.03, 0.25);
        let (w, h) = self.scene.resolution();
        let per_sample = self.sample_time.map(|t| t * f64::from(w) * f64::from(h));
        let k = match per_sample {
            Some(per_sample) if self.done > 0 => {
                ((budget / per_sample.max(1e-9)) as u32).clamp(1, left.max(1))
            }
            _ => left.min(1),
        };
        (k, budget)
    }

    /// Samples the film's frames are over: the complete ones, and the range in flight.
    fn shown(&self) -> u32 {
        self.in_flight.as_ref().map_or(self.done, |r| r.end)
    }

    /// Renders the next frame's samples until its deadline. Where the GPU's strategy keeps paths
    /// in flight ([`volpt::Backend::render_until`]), a range whose deadline passed stays in
    /// flight, its frame showing the paths that have ended, and the next frames continue it; a
    /// new epoch (a move) discards it. Samples count as done once every path of theirs has ended.
    fn render_batch(&mut self) {
        let (samples, budget) = match &self.in_flight {
            Some(range) => (range.clone(), self.batch().1),
            None => {
                let (k, budget) = self.batch();
                (self.done..self.done + k, budget)
            }
        };
        let started = Instant::now();
        let setup = started.saturating_duration_since(self.commands_taken);
        let deadline = started + Duration::from_secs_f64(budget);
        let result =
            self.backend
                .render_until(&self.scene, &mut self.film, samples.clone(), deadline);
        let elapsed = started.elapsed();
        match result {
            Ok(rendered) => {
                self.epoch_render += elapsed;
                self.range_render += elapsed;
                if rendered.samples.end == samples.end {
                    self.done = samples.end;
                    self.in_flight = None;
                    let (w, h) = self.scene.resolution();
                    let pixel_samples =
                        u64::from(w) * u64::from(h) * u64::from(samples.end - samples.start);
                    self.sample_time =
                        Some(self.range_render.as_secs_f64() / pixel_samples.max(1) as f64);
                    self.range_render = Duration::ZERO;
                    self.epoch_paths += pixel_samples;
                } else {
                    self.in_flight = Some(samples);
                }
                let frame_time = self.publish(setup, elapsed);
                if self.interactive {
                    self.adapt_scale(frame_time);
                }
            }
            Err(e) => {
                // Nothing more of this epoch: the next change tries again.
                tracing::error!("render: {e}");
                let message = ServerMessage::Error {
                    message: format!("render failed: {e}"),
                }
                .to_json();
                let _ = self.shared.notices.send(message);
                self.in_flight = None;
                self.done = self.cap();
            }
        }
    }

    /// Steps the drag resolution down when frames are slower than the budget, up when they are
    /// well within it (the gap between the thresholds keeps it from flapping).
    fn adapt_scale(&mut self, frame_time: f64) {
        if frame_time > 1.2 * INTERACTIVE_BUDGET && self.scale + 1 < SCALES.len() {
            self.scale += 1;
        } else if frame_time < 0.4 * INTERACTIVE_BUDGET && self.scale > 0 {
            self.scale -= 1;
        }
    }

    /// Tone maps, encodes and publishes the film; returns the frame's seconds (setup and render
    /// included).
    fn publish(&mut self, setup: Duration, render: Duration) -> f64 {
        let t0 = Instant::now();
        let linear = self.film.image(self.shown());
        let rgb = self.tone_map(&linear);
        let tonemap = t0.elapsed();
        let t1 = Instant::now();
        let jpeg = match encode::jpeg(&rgb, linear.width, linear.height, QUALITY) {
            Ok(jpeg) => jpeg,
            Err(e) => {
                tracing::error!("{e}");
                return render.as_secs_f64();
            }
        };
        let encode = t1.elapsed();
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let render_s = self.epoch_render.as_secs_f64();
        self.next_frame += 1;
        let header = FrameHeader {
            frame: self.next_frame,
            epoch: self.epoch,
            format: ImageFormat::Jpeg,
            width: linear.width,
            height: linear.height,
            spp: self.done,
            spp_target: self.cap(),
            spp_in_flight: self.shown() - self.done,
            interactive: self.interactive,
            setup_ms: ms(setup),
            render_ms: ms(render),
            tonemap_ms: ms(tonemap),
            encode_ms: ms(encode),
            paths_per_s: if render_s > 0.0 {
                self.epoch_paths as f64 / render_s
            } else {
                0.0
            },
            elapsed_s: self.epoch_started.elapsed().as_secs_f64(),
            exposure: self.exposure,
            variant: self.scene.variant().to_string(),
            view: self.view,
            params: self.params(),
        };
        self.shared.frames.send_replace(Some(Arc::new(Frame {
            header,
            linear,
            rgb,
            jpeg,
            png: OnceLock::new(),
        })));
        (setup + render + tonemap + encode).as_secs_f64()
    }

    /// The frame of the film (whose image is `linear`): tone mapped by the GPU that rendered
    /// it, which sends back the frame's bytes alone, or else on the CPU.
    fn tone_map(&self, linear: &Image) -> Vec<u8> {
        match self
            .backend
            .tone_map(&self.film, self.shown(), self.exposure)
        {
            Ok(Some(rgb)) => rgb,
            Ok(None) => encode::tone_map(linear, self.exposure),
            Err(e) => {
                tracing::warn!("tone mapping on the GPU failed ({e}); on the CPU instead");
                encode::tone_map(linear, self.exposure)
            }
        }
    }

    fn params(&self) -> Params {
        let float = |key| match self.scene.get(key) {
            Ok(ParamValue::Float(f)) => f,
            _ => 0.0,
        };
        Params {
            spp: self.scene.spp(),
            max_depth: match self.scene.get("max_depth") {
                Ok(ParamValue::Int(d)) => d,
                _ => -1,
            },
            medium_scale: float("medium.scale"),
            medium_albedo: match self.scene.get("medium.albedo") {
                Ok(ParamValue::Rgb(rgb)) => Some(rgb),
                _ => None,
            },
            phase_g: float("phase.g"),
            materials: self.materials(),
        }
    }

    /// The materials of a material-indexed volume, each named as its keys name it (the keys of
    /// [`Scene::params`], three a material, in table order).
    fn materials(&self) -> Vec<MaterialParams> {
        let rgb = |key: &str| match self.scene.get(key) {
            Ok(ParamValue::Rgb(v)) => v,
            _ => [0.0; 3],
        };
        self.scene
            .params()
            .iter()
            .filter_map(|(key, _)| key.strip_prefix("materials.")?.strip_suffix(".g"))
            .map(|id| MaterialParams {
                id: id.to_owned(),
                sigma_s: rgb(&format!("materials.{id}.sigma_s")),
                sigma_a: rgb(&format!("materials.{id}.sigma_a")),
                g: match self.scene.get(&format!("materials.{id}.g")) {
                    Ok(ParamValue::Float(g)) => g,
                    _ => 0.0,
                },
            })
            .collect()
    }
}

/// `commands` without the camera moves a later move of the same batch supersedes (none of the
/// scene's other changes between them): a drag sends moves faster than a frame renders, and only
/// the latest is shown, so the render thread applies that one alone instead of falling behind
/// checking each. Every other command stays, in order.
fn superseded_moves_dropped(commands: Vec<Command>) -> Vec<Command> {
    let mut kept: Vec<Command> = Vec::with_capacity(commands.len());
    // Where in `kept` the latest move is, while nothing but exposure or wake-ups followed it.
    let mut latest_move = None;
    for command in commands {
        match command {
            Command::Camera { .. } => {
                if let Some(i) = latest_move.take() {
                    kept.remove(i);
                }
                latest_move = Some(kept.len());
            }
            Command::Exposure(_) | Command::Wake => {}
            Command::Set { .. } | Command::Reset | Command::Shutdown => latest_move = None,
        }
        kept.push(command);
    }
    kept
}

fn refuse(reply: &Outbox, message: String) {
    let _ = reply.try_send(ServerMessage::Error { message }.to_json());
}

/// The loaded camera as an orbit: the target is the point of the view ray nearest the medium's
/// centre (a scene file's target is forgotten once loaded), and the up is the world axis nearest
/// the camera's up, so that orbiting keeps the horizon level.
fn initial_view(scene: &mut Scene) -> Result<View, ViewError> {
    let vec3 = |v| match v {
        Ok(ParamValue::Vec3(v)) => Ok(v),
        other => Err(ViewError::Encode(format!("camera: {other:?}"))),
    };
    let origin = vec3(scene.get("camera.origin"))?;
    let ahead = vec3(scene.get("camera.target"))?;
    let up = vec3(scene.get("camera.up"))?;
    let fov = match scene.get("camera.fov") {
        Ok(ParamValue::Float(f)) => f,
        _ => 40.0,
    };
    let sub = |a: [f32; 3], b: [f32; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f32; 3], b: [f32; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let forward = sub(ahead, origin);
    let bounds = scene.description().boundary.bounds;
    let centre = [0, 1, 2].map(|i| 0.5 * (bounds.min[i] + bounds.max[i]));
    let to_centre = sub(centre, origin);
    let distance = dot(to_centre, forward);
    // A medium behind the camera: orbit around a point as far ahead as the medium is away.
    let distance = if distance > 1e-4 {
        distance
    } else {
        dot(to_centre, to_centre).sqrt().max(1.0)
    };
    let target = [0, 1, 2].map(|i| origin[i] + forward[i] * distance);
    // The world axis nearest the camera's up (a camera tilted down at the scene has an up of
    // y 0.8 or so, still nearest +y): the axis docs/viewer.md says the orbit turns around.
    let axis = (0..3)
        .max_by(|&a, &b| up[a].abs().total_cmp(&up[b].abs()))
        .unwrap_or(1);
    let mut snapped = [0.0; 3];
    snapped[axis] = if up[axis] < 0.0 { -1.0 } else { 1.0 };
    // Looking along the world axis, the snapped up would be parallel to the view: keep the
    // camera's own up then.
    if scene.set("camera.up", ParamValue::Vec3(snapped)).is_err() {
        scene.set("camera.up", ParamValue::Vec3(up))?;
        snapped = up;
    }
    let view = View {
        origin,
        target,
        up: snapped,
        fov,
    };
    scene.set("camera.target", ParamValue::Vec3(target))?;
    Ok(view)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Of a batch of moves, the render thread applies the latest before any other change of the
    /// scene; a `set` between two moves keeps both (the first move is the one it applies to), and
    /// exposure changes and wake-ups neither keep a move nor are dropped.
    #[test]
    fn a_batch_keeps_the_latest_camera_move_before_each_change_of_the_scene() {
        let (reply, _rx) = mpsc::channel(1);
        let camera = |x: f32| Command::Camera {
            origin: [x, 0.0, 1.0],
            target: [0.0; 3],
            fov: None,
            interactive: true,
            reply: reply.clone(),
        };
        let set = Command::Set {
            key: "spp".into(),
            value: ParamValue::Int(4),
            reply: reply.clone(),
        };
        let batch = vec![
            camera(1.0),
            Command::Exposure(1.0),
            camera(2.0),
            set,
            camera(3.0),
            Command::Wake,
            camera(4.0),
            camera(5.0),
        ];
        let kept: Vec<String> = superseded_moves_dropped(batch)
            .iter()
            .map(|c| match c {
                Command::Camera { origin, .. } => format!("camera {}", origin[0]),
                Command::Set { key, .. } => format!("set {key}"),
                Command::Exposure(e) => format!("exposure {e}"),
                Command::Wake => "wake".into(),
                Command::Reset => "reset".into(),
                Command::Shutdown => "shutdown".into(),
            })
            .collect();
        assert_eq!(
            kept,
            ["exposure 1", "camera 2", "set spp", "wake", "camera 5"]
        );
    }

    /// The included example cube looks down at the cube from above (its up, made perpendicular
    /// to the view, has y 0.899): the orbit's up is still the world's +y, the axis nearest.
    #[test]
    fn the_example_cube_orbits_around_the_world_y_axis() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml");
        let mut scene = Scene::load(
            path,
            &volpt::RenderSettings {
                resolution: Some((8, 8)),
                ..volpt::RenderSettings::default()
            },
        )
        .unwrap();
        let view = initial_view(&mut scene).unwrap();
        assert_eq!(view.up, [0.0, 1.0, 0.0]);
        assert_eq!(
            scene.get("camera.up").unwrap(),
            ParamValue::Vec3([0.0, 1.0, 0.0])
        );
    }
}
