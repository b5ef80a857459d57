//! Light arriving from infinitely far away.

use crate::{Spectrum, Vec3};

pub trait Environment {
    /// Radiance arriving along the propagation direction `-dir`, i.e. seen when looking along `dir`.
    fn radiance(&self, dir: Vec3) -> Spectrum;
}

#[derive(Clone, Copy, Debug)]
pub struct ConstantEnvironment(pub Spectrum);

impl Environment for ConstantEnvironment {
    #[inline]
    fn radiance(&self, _dir: Vec3) -> Spectrum {
        self.0
    }
}
