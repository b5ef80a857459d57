//! The viewer's WebSocket protocol: what a page sends (JSON text messages) and what the server
//! answers (a JSON `hello` and `error` as text; frames as binary messages).
//!
//! Client to server, one JSON object per text message, at most [`MAX_MESSAGE_BYTES`]:
//! - `{"type":"camera","origin":[x,y,z],"target":[x,y,z],"fov":deg?,"interactive":bool}`: look
//!   from `origin` at `target` (the orbit centre), keeping the world up of `hello`. `interactive`
//!   while the user drags: reduced resolution, one sample per frame.
//! - `{"type":"set","key":K,"value":V}`: a scene parameter, `K` one of [`SETTABLE`] or a
//!   material's coefficient, `materials.<m>.sigma_s`, `.sigma_a` (`[r, g, b]`) or `.g` (a number)
//!   (`<m>` the material's name or index, [`MaterialParams::id`]).
//! - `{"type":"exposure","value":stops}`: the tone mapping's exposure (no new accumulation).
//! - `{"type":"format","format":"jpeg"|"png"}`: how this client's frames are encoded.
//! - `{"type":"ack","frame":id}`: frame `id` arrived; at most [`MAX_IN_FLIGHT`] are unacknowledged.
//! - `{"type":"reset"}`: the camera as loaded.
//!
//! Server to client:
//! - text `{"type":"hello",...}` ([`Hello`]) once, on connection;
//! - text `{"type":"error","message":...}` for a message refused; nothing else changes;
//! - binary frames: a little-endian u32 `n`, `n` bytes of JSON [`FrameHeader`], then the image
//!   (JPEG or PNG).

use serde::{Deserialize, Serialize};
use volpt::ParamValue;

/// The largest message a client may send; a longer one closes its connection (code 1009).
pub const MAX_MESSAGE_BYTES: usize = 4096;

/// Frames sent to a client and not yet acknowledged, at most.
pub const MAX_IN_FLIGHT: usize = 2;

/// The parameters a `set` message may change (the camera moves by `camera` messages), besides
/// the materials' ([`MATERIAL_FIELDS`]).
pub const SETTABLE: &[&str] = &[
    "spp",
    "seed",
    "max_depth",
    "rr_depth",
    "medium.scale",
    "medium.albedo",
    "phase.g",
    "camera.fov",
    "sun.direction",
    "sun.irradiance",
    "sun.angular_radius",
    "light.position",
    "light.intensity",
    "light.direction",
];

/// What `materials.<m>.` may be followed by in a `set` message: RGB, RGB, a number.
pub const MATERIAL_FIELDS: [&str; 3] = ["sigma_s", "sigma_a", "g"];

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ImageFormat {
    #[default]
    Jpeg,
    Png,
}

/// A message from a page.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum ClientMessage {
    Camera {
        origin: [f32; 3],
        target: [f32; 3],
        #[serde(default)]
        fov: Option<f32>,
        #[serde(default)]
        interactive: bool,
    },
    Set {
        key: String,
        value: serde_json::Value,
    },
    Exposure {
        value: f32,
    },
    Format {
        format: ImageFormat,
    },
    Ack {
        frame: u64,
    },
    Reset,
}

/// Why a client's message was refused (sent back as an `error` message).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ProtocolError {
    #[error("malformed message: {0}")]
    Malformed(String),
    #[error("{0}")]
    Invalid(String),
}

impl ClientMessage {
    /// Parses and checks a text message: a well-formed message of finite numbers.
    pub fn parse(text: &str) -> Result<Self, ProtocolError> {
        let message: ClientMessage =
            serde_json::from_str(text).map_err(|e| ProtocolError::Malformed(e.to_string()))?;
        let finite = |v: &[f32]| v.iter().all(|c| c.is_finite());
        match &message {
            ClientMessage::Camera {
                origin,
                target,
                fov,
                ..
            } if !finite(origin) || !finite(target) || fov.is_some_and(|f| !f.is_finite()) => Err(
                ProtocolError::Invalid("camera: expected finite numbers".into()),
            ),
            // Exposure is a power of two of the image: beyond +-64 stops every pixel is black or
            // white in f32.
            ClientMessage::Exposure { value } if !(-64.0..=64.0).contains(value) => {
                Err(ProtocolError::Invalid(format!(
                    "exposure: expected -64 to 64 stops, found {value}"
                )))
            }
            _ => Ok(message),
        }
    }
}

/// A `set` message's value as the parameter `key` takes it (the facade checks its range).
pub fn param_value(key: &str, value: &serde_json::Value) -> Result<ParamValue, ProtocolError> {
    let wrong = |expected: &str| {
        ProtocolError::Invalid(format!("{key}: expected {expected}, found {value}"))
    };
    let number = || value.as_f64().filter(|v| v.is_finite());
    let rgb = || {
        let rgb: Option<Vec<f32>> = value.as_array().and_then(|a| {
            a.iter()
                .map(|c| c.as_f64().filter(|v| v.is_finite()).map(|v| v as f32))
                .collect()
        });
        match rgb.as_deref() {
            Some(&[r, g, b]) => Ok(ParamValue::Rgb([r, g, b])),
            _ => Err(wrong("three numbers ([r, g, b] or [x, y, z])")),
        }
    };
    let field = key
        .strip_prefix("materials.")
        .and_then(|rest| rest.rsplit_once('.'))
        .filter(|(id, _)| !id.is_empty())
        .map(|(_, field)| field);
    match (key, field) {
        (_, Some("sigma_s" | "sigma_a")) => return rgb(),
        (_, Some("g")) => {
            return number()
                .filter(|v| v.abs() <= f64::from(f32::MAX))
                .map(|v| ParamValue::Float(v as f32))
                .ok_or_else(|| wrong("a number"))
        }
        _ => {}
    }
    match key {
        "spp" | "seed" | "max_depth" | "rr_depth" => value
            .as_i64()
            .map(ParamValue::Int)
            .ok_or_else(|| wrong("an integer")),
        "medium.scale" | "phase.g" | "camera.fov" | "sun.angular_radius" => number()
            .filter(|v| v.abs() <= f64::from(f32::MAX))
            .map(|v| ParamValue::Float(v as f32))
            .ok_or_else(|| wrong("a number")),
        "medium.albedo" | "sun.direction" | "sun.irradiance" | "light.position"
        | "light.intensity" | "light.direction" => rgb(),
        _ => Err(ProtocolError::Invalid(format!(
            "set: unknown parameter {key:?} (expected one of {}, or materials.<name>.{})",
            SETTABLE.join(", "),
            MATERIAL_FIELDS.join("|")
        ))),
    }
}

/// A camera as the page orbits it: the target is the orbit centre, not a point one unit ahead.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct View {
    pub origin: [f32; 3],
    pub target: [f32; 3],
    pub up: [f32; 3],
    pub fov: f32,
}

/// The scene parameters the page shows; `None` where the scene has no such value.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Params {
    pub spp: u32,
    pub max_depth: i64,
    pub medium_scale: f32,
    /// `None` for an albedo grid.
    pub medium_albedo: Option<[f32; 3]>,
    pub phase_g: f32,
    /// A material-indexed volume's materials, in table order (none for another medium).
    pub materials: Vec<MaterialParams>,
}

/// A material's coefficients as the page shows and edits them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MaterialParams {
    /// What names it in a key, `materials.<id>.sigma_s`: its name, or its index where the name
    /// is empty or not unique.
    pub id: String,
    pub sigma_s: [f32; 3],
    pub sigma_a: [f32; 3],
    pub g: f32,
}

/// Sent once on connection: what is rendered where, and the view to reset to.
#[derive(Clone, Debug, Serialize)]
pub struct Hello {
    pub scene: String,
    pub backend: String,
    pub device: String,
    pub strategy: Option<String>,
    pub math: Option<String>,
    pub width: u32,
    pub height: u32,
    /// The view as loaded (`reset` returns to it).
    pub initial: View,
    pub max_message_bytes: usize,
    pub max_in_flight: usize,
}

#[derive(Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum ServerMessage<'a> {
    Hello(&'a Hello),
    Error { message: String },
}

impl ServerMessage<'_> {
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_else(|e| {
            // Serialising these plain structs cannot fail; say so rather than panic if it does.
            format!(r#"{{"type":"error","message":"internal: {e}"}}"#)
        })
    }
}

/// The JSON before a frame's image.
#[derive(Clone, Debug, Serialize)]
pub struct FrameHeader {
    /// Increases with every frame the server makes (the `ack` names it).
    pub frame: u64,
    /// Increases with every change of view or parameter: frames of one epoch refine one image.
    pub epoch: u64,
    pub format: ImageFormat,
    pub width: u32,
    pub height: u32,
    /// Samples per pixel in this frame, and the number the accumulation stops at.
    pub spp: u32,
    pub spp_target: u32,
    /// Samples whose paths are still in flight on the GPU (the frame shows those that have
    /// ended: a multi-kernel strategy's frame stopped at its deadline); 0 otherwise.
    pub spp_in_flight: u32,
    pub interactive: bool,
    /// Milliseconds the render thread spent before this frame's render on the commands it took
    /// (camera moves and parameters checked and applied, a new epoch started).
    pub setup_ms: f64,
    /// Milliseconds of this frame's render (its new samples), tone mapping and JPEG encoding.
    pub render_ms: f64,
    pub tonemap_ms: f64,
    pub encode_ms: f64,
    /// Paths per second over the epoch's renders, and seconds since the epoch began.
    pub paths_per_s: f64,
    pub elapsed_s: f64,
    pub exposure: f32,
    pub variant: String,
    pub view: View,
    pub params: Params,
}

/// A binary frame message: header length, header, image.
pub fn frame_message(header: &FrameHeader, image: &[u8]) -> Vec<u8> {
    let json = serde_json::to_vec(header).unwrap_or_default();
    let mut out = Vec::with_capacity(4 + json.len() + image.len());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&json);
    out.extend_from_slice(image);
    out
}

/// Splits a binary frame message into its header JSON and image (the test client's side).
pub fn split_frame(message: &[u8]) -> Option<(serde_json::Value, &[u8])> {
    let n = u32::from_le_bytes(message.get(..4)?.try_into().ok()?) as usize;
    let json = message.get(4..4usize.checked_add(n)?)?;
    Some((serde_json::from_slice(json).ok()?, &message[4 + n..]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_parse_and_bad_ones_are_refused_with_a_reason() {
        assert!(matches!(
            ClientMessage::parse(r#"{"type":"camera","origin":[1,2,3],"target":[0,0,0]}"#),
            Ok(ClientMessage::Camera {
                interactive: false,
                fov: None,
                ..
            })
        ));
        for bad in [
            "",
            "{",
            "[]",
            r#"{"type":"fly"}"#,
            r#"{"type":"camera","origin":[1,2],"target":[0,0,0]}"#,
            r#"{"type":"camera","origin":[1,2,1e39],"target":[0,0,0]}"#,
            r#"{"type":"exposure","value":1000}"#,
            r#"{"type":"ack","frame":-1}"#,
        ] {
            assert!(ClientMessage::parse(bad).is_err(), "{bad:?} was accepted");
        }
    }

    #[test]
    fn set_values_are_typed_by_key() {
        let v = |s: &str| serde_json::from_str::<serde_json::Value>(s).unwrap();
        assert_eq!(param_value("max_depth", &v("-1")), Ok(ParamValue::Int(-1)));
        assert_eq!(
            param_value("medium.albedo", &v("[0.5, 1, 0]")),
            Ok(ParamValue::Rgb([0.5, 1.0, 0.0]))
        );
        assert!(param_value("max_depth", &v("1.5")).is_err());
        assert!(param_value("medium.albedo", &v("[1, 2]")).is_err());
        assert!(param_value("camera.origin", &v("[1, 2, 3]")).is_err());
        assert!(param_value("phase.g", &v("\"0.5\"")).is_err());
        // A material's keys, by name or index (the facade knows which materials there are).
        assert_eq!(
            param_value("materials.cyan.sigma_a", &v("[6, 0.8, 0.2]")),
            Ok(ParamValue::Rgb([6.0, 0.8, 0.2]))
        );
        assert_eq!(
            param_value("materials.0.g", &v("0.3")),
            Ok(ParamValue::Float(0.3))
        );
        assert!(param_value("materials.cyan.sigma_s", &v("1")).is_err());
        assert!(param_value("materials.cyan.g", &v("[1, 2, 3]")).is_err());
        assert!(param_value("materials.cyan.colour", &v("[1, 2, 3]")).is_err());
        assert!(param_value("materials..g", &v("0.3")).is_err());
    }

    #[test]
    fn a_frame_message_splits_into_its_header_and_image() {
        let header = serde_json::json!({"frame": 7});
        let json = serde_json::to_vec(&header).unwrap();
        let mut message = (json.len() as u32).to_le_bytes().to_vec();
        message.extend(&json);
        message.extend([1, 2, 3]);
        let (h, image) = split_frame(&message).unwrap();
        assert_eq!(h["frame"], 7);
        assert_eq!(image, [1, 2, 3]);
        assert!(split_frame(&[255, 255, 255, 255, 0]).is_none());
    }
}
