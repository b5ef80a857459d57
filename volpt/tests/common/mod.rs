//! What the facade's integration tests share.

// Each test crate that includes this module uses a part of it.
#![allow(dead_code)]

use std::sync::atomic::{AtomicU32, Ordering};
use std::time::Duration;

use volpt::{Backend, Film, Observer, Quiet, Scene};

/// The scene's whole film, rendered on the CPU.
pub fn render(scene: &Scene) -> Film {
    let mut film = scene.film();
    Backend::cpu()
        .render(scene, &mut film, 0..scene.spp(), &Quiet)
        .unwrap();
    film
}

/// Cancels at the `after`-th look, asking for a look after every sample.
pub struct CancelAfter {
    looks: AtomicU32,
    after: u32,
}

impl CancelAfter {
    pub fn new(after: u32) -> Self {
        Self {
            looks: AtomicU32::new(0),
            after,
        }
    }
}

impl Observer for CancelAfter {
    fn cancelled(&self) -> bool {
        self.looks.fetch_add(1, Ordering::SeqCst) + 1 >= self.after
    }
    fn check_every(&self) -> Option<Duration> {
        Some(Duration::ZERO)
    }
}
