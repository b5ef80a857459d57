//! The numbers of a description that a scene takes between renders without reloading (the
//! facade's `Scene::get` and `Scene::set`), declared by the axis that holds them.

/// One number a scene takes between renders.
#[derive(Clone, Copy, Debug)]
pub struct NumberParam {
    /// The facade's key, `<axis>.<name>`.
    pub key: &'static str,
    /// What it is, in words.
    pub about: &'static str,
    /// Whether `value` is one it takes.
    pub accepts: fn(f32) -> bool,
    /// What [`NumberParam::accepts`] takes, in words.
    pub expected: &'static str,
}
