//! Third-party decoders (`vtkio`, `exr`) that panic on some malformed files: their panics are
//! caught and become the caller's decode errors, and their messages are kept off stderr, so that a
//! user sees one clear error and no panic.

use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Once;

thread_local! {
    /// Whether this thread is inside a decoder whose panics [`contain_panics`] catches.
    static CONTAINED: Cell<bool> = const { Cell::new(false) };
}

/// Runs `decode`, catching a panic. The panic hook is wrapped once per process to skip panics on a
/// thread inside `decode`; every other panic reaches the previous hook as before.
pub(crate) fn contain_panics<T>(decode: impl FnOnce() -> T) -> std::thread::Result<T> {
    static WRAP_HOOK: Once = Once::new();
    WRAP_HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !CONTAINED.with(Cell::get) {
                previous(info);
            }
        }));
    });
    let outer = CONTAINED.with(|flag| flag.replace(true));
    let result = catch_unwind(AssertUnwindSafe(decode));
    CONTAINED.with(|flag| flag.set(outer));
    result
}
