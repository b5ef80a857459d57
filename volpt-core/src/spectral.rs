//! The spectral part of a path's state, sized by its medium ([`crate::Medium::Spectral`]): nothing
//! for a grey extinction, the hero channel and its rescaled path densities for a chromatic one.
//!
//! Tracking, transmittance and the weight of the light a path gathers are written once in
//! [`crate::path`] over this trait: a grey medium's path carries no spectral bytes (a strategy
//! that parks paths in memory moves no more than it did before chromatic media) and compiles
//! plain delta and ratio tracking; a chromatic medium's compiles their spectral-MIS forms
//! ([`crate::chromatic`]).

use core::fmt::Debug;
use core::ops::MulAssign;

use crate::chromatic::choose_hero;
use crate::flight::FlightEnd;
use crate::medium::Medium;
use crate::rng::Rng;
use crate::tracking::{
    delta_tracking, ratio_tracking, spectral_delta_tracking, spectral_ratio_tracking, FreeFlight,
};
use crate::{Ray, Spectrum};

/// What a path carries for its medium's extinction, and the estimators that read it.
pub trait SpectralState: Copy + Debug {
    /// A transmittance estimate: one number for a grey extinction, one per channel otherwise.
    type Transmittance: Copy + MulAssign;

    /// The state of a path leaving the camera (a chromatic path draws its hero here).
    fn start(rng: &mut Rng) -> Self;

    /// What the path's light is multiplied by, given its throughput.
    fn weight(&self, throughput: Spectrum) -> Spectrum;

    /// Samples the distance to the next real collision along `ray` before `t_max`.
    fn free_flight<M: Medium>(
        &mut self,
        medium: &M,
        ray: &Ray,
        t_max: impl FlightEnd,
        rng: &mut Rng,
        steps: &mut u32,
        max_steps: u32,
    ) -> FreeFlight;

    /// Whether the path weighs nothing any more (it ends).
    fn is_void(&self) -> bool;

    /// An unbiased estimate of the transmittance along `ray` up to `t_max`; `None` when the step
    /// budget ran out.
    fn transmittance<M: Medium>(
        medium: &M,
        ray: &Ray,
        t_max: f32,
        rng: &mut Rng,
        steps: &mut u32,
        max_steps: u32,
    ) -> Option<Self::Transmittance>;

    /// Whether a transmittance estimate is above zero in some channel.
    fn transmits(t: Self::Transmittance) -> bool;

    /// The light next-event estimation adds: `light` seen through `transmittance`, with the MIS
    /// weight `mis`, the phase function's value `phase` and the light sample's density `pdf`.
    fn next_event_light(
        &self,
        throughput: Spectrum,
        light: Spectrum,
        mis: f32,
        phase: f32,
        pdf: f32,
        transmittance: Self::Transmittance,
    ) -> Spectrum;
}

/// A grey extinction: the path carries nothing spectral.
impl SpectralState for () {
    type Transmittance = f32;

    #[inline(always)]
    fn start(_: &mut Rng) -> Self {}

    #[inline(always)]
    fn weight(&self, throughput: Spectrum) -> Spectrum {
        throughput
    }

    #[inline(always)]
    fn free_flight<M: Medium>(
        &mut self,
        medium: &M,
        ray: &Ray,
        t_max: impl FlightEnd,
        rng: &mut Rng,
        steps: &mut u32,
        max_steps: u32,
    ) -> FreeFlight {
        delta_tracking(medium, ray, t_max, rng, steps, max_steps)
    }

    #[inline(always)]
    fn is_void(&self) -> bool {
        false
    }

    #[inline(always)]
    fn transmittance<M: Medium>(
        medium: &M,
        ray: &Ray,
        t_max: f32,
        rng: &mut Rng,
        steps: &mut u32,
        max_steps: u32,
    ) -> Option<f32> {
        ratio_tracking(medium, ray, t_max, rng, steps, max_steps)
    }

    #[inline(always)]
    fn transmits(t: f32) -> bool {
        t > 0.0
    }

    #[inline(always)]
    fn next_event_light(
        &self,
        throughput: Spectrum,
        light: Spectrum,
        mis: f32,
        phase: f32,
        pdf: f32,
        transmittance: f32,
    ) -> Spectrum {
        throughput * light * (mis * phase * transmittance / pdf)
    }
}

/// A chromatic extinction's path state: the channel whose extinction samples the path's
/// collisions, and the path's density under each channel over their mean (pbrt-v4's rescaled
/// `r_u`; mean 1, each in `[0, 3]`): the light the path gathers is `throughput * r_u`
/// ([`crate::chromatic`]).
///
/// The hero is a `u32`, not a `u8`: the state is then 16 bytes of 4-byte words without padding,
/// which a parked path copies in registers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeroChannel {
    pub r_u: Spectrum,
    pub hero: u32,
}

impl SpectralState for HeroChannel {
    type Transmittance = Spectrum;

    #[inline(always)]
    fn start(rng: &mut Rng) -> Self {
        Self {
            r_u: Spectrum::ONE,
            hero: choose_hero(rng) as u32,
        }
    }

    #[inline(always)]
    fn weight(&self, throughput: Spectrum) -> Spectrum {
        throughput * self.r_u
    }

    #[inline(always)]
    fn free_flight<M: Medium>(
        &mut self,
        medium: &M,
        ray: &Ray,
        t_max: impl FlightEnd,
        rng: &mut Rng,
        steps: &mut u32,
        max_steps: u32,
    ) -> FreeFlight {
        spectral_delta_tracking(
            medium,
            ray,
            t_max,
            rng,
            self.hero as u8,
            &mut self.r_u,
            steps,
            max_steps,
        )
    }

    /// No channel's density is left (`chromatic::rescale`).
    #[inline(always)]
    fn is_void(&self) -> bool {
        self.r_u == Spectrum::ZERO
    }

    #[inline(always)]
    fn transmittance<M: Medium>(
        medium: &M,
        ray: &Ray,
        t_max: f32,
        rng: &mut Rng,
        steps: &mut u32,
        max_steps: u32,
    ) -> Option<Spectrum> {
        spectral_ratio_tracking(medium, ray, t_max, rng, steps, max_steps)
    }

    #[inline(always)]
    fn transmits(t: Spectrum) -> bool {
        t.max_element() > 0.0
    }

    /// Each channel's transmittance, estimated at once; the path's weight carries the MIS.
    #[inline(always)]
    fn next_event_light(
        &self,
        throughput: Spectrum,
        light: Spectrum,
        mis: f32,
        phase: f32,
        pdf: f32,
        transmittance: Spectrum,
    ) -> Spectrum {
        self.weight(throughput) * transmittance * light * (mis * phase / pdf)
    }
}
