//! The names of generic parts, composed at compile time from their type parameters' own names:
//! `GridMedium<ConstantAlbedo, AnyLayout>` is `grid_density__constant_albedo__any_layout`, so two
//! instantiations of one generic part never share a name, and a new parameter type names itself.
//!
//! Stable Rust cannot size an array by a generic parameter's name length, so a name is written
//! into [`CAPACITY`] bytes and cut to its length; it is evaluated in constants only (a name too
//! long for the capacity fails the build), with no allocation, as the `no_std` kernels need.

/// The longest name a composition may have, in bytes.
pub const CAPACITY: usize = 96;

/// What joins the generic part's own name and its parameters' names: two underscores, since a
/// name is lower case with its words joined by one.
pub const SEPARATOR: &str = "__";

/// A name composed of parts, in a buffer of [`CAPACITY`] bytes.
pub struct Joined {
    bytes: [u8; CAPACITY],
    len: usize,
}

impl Joined {
    /// `parts` joined by [`SEPARATOR`]. Panics (a build error, in a constant) if the name exceeds
    /// [`CAPACITY`].
    pub const fn new(parts: &[&str]) -> Self {
        let mut joined = Self {
            bytes: [0; CAPACITY],
            len: 0,
        };
        let mut i = 0;
        while i < parts.len() {
            if i > 0 {
                joined.push(SEPARATOR);
            }
            joined.push(parts[i]);
            i += 1;
        }
        joined
    }

    const fn push(&mut self, part: &str) {
        let part = part.as_bytes();
        assert!(
            self.len + part.len() <= CAPACITY,
            "a composed part name exceeds volpt_core::abi::name::CAPACITY"
        );
        let mut i = 0;
        while i < part.len() {
            self.bytes[self.len] = part[i];
            self.len += 1;
            i += 1;
        }
    }

    /// The name. A `Joined` borrowed for `'static` is a promoted constant.
    pub const fn as_str(&'static self) -> &'static str {
        match core::str::from_utf8(self.bytes.split_at(self.len).0) {
            Ok(name) => name,
            // Whole UTF-8 strings joined by ASCII are UTF-8.
            Err(_) => unreachable!(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Joined;

    const NAME: &str = Joined::new(&["grid_density", "constant_albedo", "any_layout"]).as_str();
    const ALONE: &str = Joined::new(&["homogeneous"]).as_str();

    #[test]
    fn parts_are_joined_by_the_separator() {
        assert_eq!(NAME, "grid_density__constant_albedo__any_layout");
        assert_eq!(ALONE, "homogeneous");
    }
}
