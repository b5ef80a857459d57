//! [`Observer`]: what a render tells its caller while it runs, and how the caller stops it.

use std::time::Duration;

/// Receives a render's progress and notes, and may stop it. Every method has a default that does
/// nothing, so an observer implements only what it needs.
pub trait Observer: Sync {
    /// `done` of `total` paths of this render traced (called from render threads).
    fn progress(&self, _done: u64, _total: u64) {}

    /// A message for the user: `auto`'s calibration and its choice.
    fn note(&self, _text: &str) {}

    /// Looked at between chunks of samples: `true` ends the render after the chunk in flight,
    /// with every finished sample in the film.
    fn cancelled(&self) -> bool {
        false
    }

    /// How much rendering may pass between looks at [`Observer::cancelled`]: the render runs in
    /// chunks of samples that grow towards this. `None` renders the whole range in one go (the
    /// fastest on a GPU: one launch, one tail).
    fn check_every(&self) -> Option<Duration> {
        None
    }
}

/// An observer that shows nothing and never cancels.
#[derive(Clone, Copy, Debug, Default)]
pub struct Quiet;

impl Observer for Quiet {}
