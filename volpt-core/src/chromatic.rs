//! A medium whose extinction differs between R, G and B (milk, skin, a print's resins), and the
//! spectral MIS that tracks it without bias and without the variance of one channel's tracking.
//!
//! `sigma_t(p) = extinction * density(p)`: an RGB extinction times an optional density grid (none:
//! density 1, a homogeneous chromatic medium) of one channel, or of three (a density per channel:
//! Mitsuba's RGB `sigma_t` `gridvolume`); the albedo is a constant or an RGB grid; RGB grids are
//! read trilinearly or, where their lookup says so, nearest. Or a
//! material-indexed volume ([`crate::material`]): extinction, albedo and phase asymmetry from the
//! table row of the voxel's material. Which of these a medium has is a run-time branch inside the
//! one type, so chromatic media add one value to the registry's medium axis, not a cartesian
//! product of their own.
//!
//! Tracking ([`crate::tracking::spectral_delta_tracking`]) gives each channel its own majorant
//! (a homogeneous medium's exact `sigma_t,c`; per majorant-grid cell, `extinction_c` times the
//! cell's largest density, or a material-indexed volume's per-channel bound of the materials
//! there), samples each free flight at the majorant of one channel chosen per path (its *hero*)
//! and weights the path by single-sample MIS over the three channels' path densities with the
//! balance heuristic (Miller, Georgiev, Jarosz 2019, "A null-scattering path integral formulation
//! of light transport"; pbrt-v4's `VolPathIntegrator` and its rescaled path probabilities `r_u`;
//! Mitsuba 3's `volpathmis` on homogeneous media). Under channel `c` an event at `x`, an optical
//! depth `tau_c` of its majorant after the previous one, has density `exp(-tau_c) sigma_t,c(x)` (a
//! real collision), `exp(-tau_c) (m_c - sigma_t,c(x))` (a null one) or `exp(-tau_c)` (leaving the
//! medium). The path's contribution in channel `c` is `f_c / mean_j p_j = (f_c / p_c) * r_c` with
//! `r_c = p_c / mean_j p_j`: `f_c / p_c` is what a grey medium's throughput already holds (albedos,
//! BSDF weights, roulette; a null collision's `sigma_n / sigma_n` is 1), and [`rescale`] keeps `r`
//! ([`HeroChannel::r_u`]) event by event. Every `r_c` stays in `[0, 3]` and finite by construction;
//! a path whose `r` would be all zero (its hero's density underflowed) ends, which loses only light
//! below f32's range. A homogeneous medium has no null collision in any channel, where one
//! majorant for all channels (the largest) gave the weaker heroes null collisions whose rescaling
//! added variance (1.1-1.5x per channel on a cube of channels 5x apart,
//! `own_channel_majorants_lower_the_variance_at_equal_samples`).

use bytemuck::{Pod, Zeroable};

use crate::abi::{Component, GridParams, Upload};
use crate::grid::{DenseTrilinear, Grid, GridLookup, GridPlacement, GridReads};
use crate::majorant::{build_majorants, MajorantGrid, MajorantGridParams};
use crate::material::{MaterialGrid, MaterialGridParams};
use crate::medium::{Medium, TrackedMedium};
use crate::rng::Rng;
use crate::spectral::HeroChannel;
use crate::{Spectrum, Vec3};

/// A chromatic medium: `sigma_t(p) = extinction * density(p)` per channel, read trilinearly.
#[derive(Clone, Copy, Debug)]
pub struct ChromaticMedium<'a> {
    /// The extinction per channel where the density is 1.
    pub extinction: Spectrum,
    /// `None`: the density is 1 everywhere (a homogeneous medium), unless `density_rgb` has it.
    pub density: Option<Grid<'a, 1>>,
    /// A density per channel (read where `density` is `None`): `extinction` then scales each
    /// channel of this grid.
    pub density_rgb: Option<Grid<'a, 3>>,
    /// `max(extinction) * max(density)`: a bound of every channel.
    pub majorant: f32,
    /// Per-cell bounds of every channel ([`crate::majorant`]); `None` tracks with `majorant`.
    pub majorants: Option<MajorantGrid<'a>>,
    /// Each channel's own bound over the medium (`extinction * max(density)`, or per channel
    /// the largest of the materials present): its majorant where `majorants` is `None`, and
    /// per cell `channel_majorant * cell bound / majorant` unless `channel_majorants` has it.
    pub channel_majorant: Spectrum,
    /// Each channel's bound per cell of `majorants`, three `f32`s a cell (a material-indexed
    /// volume's, whose channels' bounds are not in proportion from cell to cell).
    pub channel_majorants: Option<&'a [f32]>,
    /// The albedo where there is no albedo grid.
    pub albedo: Spectrum,
    pub albedo_grid: Option<Grid<'a, 3>>,
    /// A material-indexed volume, which then alone gives the extinction, albedo and phase
    /// asymmetry (`extinction`, `density`, `albedo` and `albedo_grid` are not read).
    pub materials: Option<MaterialGrid<'a>>,
}

impl<'a> ChromaticMedium<'a> {
    /// A medium of `extinction` times `density`, whose majorant is derived from them.
    pub fn new(
        extinction: Spectrum,
        density: Option<Grid<'a, 1>>,
        albedo: Spectrum,
        albedo_grid: Option<Grid<'a, 3>>,
    ) -> Self {
        let max_density = density.map_or(1.0, |g| g.samples().iter().copied().fold(0.0, f32::max));
        Self {
            extinction,
            density,
            density_rgb: None,
            majorant: extinction.max_element() * max_density,
            majorants: None,
            channel_majorant: extinction * max_density,
            channel_majorants: None,
            albedo,
            albedo_grid,
            materials: None,
        }
    }

    /// A medium of `extinction` times a density per channel (`density`'s three), whose
    /// majorants are derived from them: each channel's is its own largest density times its
    /// extinction.
    pub fn per_channel(
        extinction: Spectrum,
        density: Grid<'a, 3>,
        albedo: Spectrum,
        albedo_grid: Option<Grid<'a, 3>>,
    ) -> Self {
        let mut max_density = Spectrum::ZERO;
        for v in density.samples().chunks_exact(3) {
            max_density = max_density.max(Spectrum::new(v[0], v[1], v[2]));
        }
        let channel_majorant = extinction * max_density;
        Self {
            extinction,
            density: None,
            density_rgb: Some(density),
            majorant: channel_majorant.max_element(),
            majorants: None,
            channel_majorant,
            channel_majorants: None,
            albedo,
            albedo_grid,
            materials: None,
        }
    }

    /// The medium of a material-indexed volume, whose majorant is its materials' largest
    /// extinction.
    pub fn indexed(materials: MaterialGrid<'a>) -> Self {
        Self {
            extinction: Spectrum::ZERO,
            density: None,
            density_rgb: None,
            majorant: materials.max_extinction(),
            majorants: None,
            channel_majorant: materials.max_extinction_rgb(),
            channel_majorants: None,
            albedo: Spectrum::ZERO,
            albedo_grid: None,
            materials: Some(materials),
        }
    }
}

impl Medium for ChromaticMedium<'_> {
    type Spectral = HeroChannel;
    const HOMOGENEOUS: bool = false;

    #[inline]
    fn majorant(&self) -> f32 {
        self.majorant
    }

    #[inline]
    fn majorant_grid(&self) -> Option<&MajorantGrid<'_>> {
        self.majorants.as_ref()
    }

    /// A cell's from [`ChromaticMedium::channel_majorants`] where it has them; else the global
    /// bounds scaled as the cell's bound of every channel is (`extinction * density` keeps the
    /// channels in proportion), or for a material-indexed volume or a density per channel that
    /// bound in every channel.
    #[inline(always)]
    fn majorant_rgb(&self, bound: f32, cell: Option<usize>) -> Spectrum {
        let Some(cell) = cell else {
            return self.channel_majorant;
        };
        if let Some(channels) = self.channel_majorants {
            let c = &channels[3 * cell..3 * cell + 3];
            return Spectrum::new(c[0], c[1], c[2]);
        }
        if self.materials.is_some() || self.density_rgb.is_some() {
            // Such channels are not in proportion: only the bound of all holds for each.
            return Spectrum::splat(bound);
        }
        if self.majorant > 0.0 {
            self.channel_majorant * (bound / self.majorant)
        } else {
            Spectrum::ZERO
        }
    }

    /// The largest channel's extinction.
    #[inline(always)]
    fn sigma_t(&self, p: Vec3) -> f32 {
        self.sigma_t_rgb(p).max_element()
    }

    #[inline(always)]
    fn sigma_t_rgb(&self, p: Vec3) -> Spectrum {
        if let Some(materials) = &self.materials {
            return materials.sigma_t(p);
        }
        match (&self.density, &self.density_rgb) {
            (Some(grid), _) => self.extinction * DenseTrilinear::lookup(grid, p)[0],
            (None, Some(grid)) => self.extinction * Spectrum::from_array(read(grid, p)),
            (None, None) => self.extinction,
        }
    }

    #[inline(always)]
    fn uniform_sigma_t_rgb(&self) -> Option<Spectrum> {
        if let Some(materials) = &self.materials {
            return materials.uniform_sigma_t();
        }
        match (self.density, self.density_rgb) {
            (None, None) => Some(self.extinction),
            _ => None,
        }
    }

    #[inline(always)]
    fn albedo(&self, p: Vec3) -> Spectrum {
        if let Some(materials) = &self.materials {
            return materials.albedo(p);
        }
        match &self.albedo_grid {
            Some(grid) => Spectrum::from_array(read(grid, p)),
            None => self.albedo,
        }
    }

    #[inline(always)]
    fn phase_g(&self, p: Vec3) -> Option<f32> {
        self.materials.as_ref().map(|m| m.g(p))
    }
}

impl<'a> TrackedMedium<'a> for ChromaticMedium<'a> {
    /// The density scaled by the largest channel: its majorant grid bounds every channel.
    fn density(&self) -> Option<(Grid<'a, 1>, f32)> {
        self.density.map(|g| (g, self.extinction.max_element()))
    }

    fn channel_densities(&self) -> Option<(Grid<'a, 3>, Spectrum)> {
        self.density_rgb.map(|g| (g, self.extinction))
    }

    fn track_with(&mut self, grid: Option<MajorantGrid<'a>>) {
        self.majorants = grid;
    }

    fn track_channels_with(&mut self, channels: Option<&'a [f32]>) {
        self.channel_majorants = channels;
    }

    fn materials(&self) -> Option<MaterialGrid<'a>> {
        self.materials
    }
}

/// A dense grid's value at `p`, trilinear, or the nearest sample's where the grid says so (an
/// RGB grid exported from a material-indexed volume, Mitsuba's `filter_type` `nearest`): a
/// run-time branch, the trilinear read's arithmetic unchanged.
#[inline(always)]
fn read(grid: &Grid<'_, 3>, p: Vec3) -> [f32; 3] {
    if grid.lookup == GridLookup::Nearest {
        grid.lookup_dense_nearest(p)
    } else {
        DenseTrilinear::lookup(grid, p)
    }
}

/// Fills `channels` (three values per cell of a `res` grid over `bounds`, x fastest) with each
/// channel's bound of `extinction * density` inside each cell, and `bound` (one per cell) with
/// the largest of the three: [`build_majorants`] of each channel, copied in turn into `plane`
/// (one value per sample; the grid's samples are interleaved).
pub fn build_channel_majorants(
    density: &Grid<'_, 3>,
    extinction: Spectrum,
    bounds: crate::Aabb,
    res: [u32; 3],
    plane: &mut [f32],
    channels: &mut [f32],
    bound: &mut [f32],
) {
    assert_eq!(
        channels.len(),
        3 * bound.len(),
        "three channel bounds a cell"
    );
    assert_eq!(
        3 * plane.len(),
        density.data.len(),
        "one plane value a sample"
    );
    for c in 0..3 {
        for (v, s) in plane.iter_mut().zip(density.data.chunks_exact(3)) {
            *v = s[c];
        }
        let one = Grid::<1>::new(plane, density.res, density.mapping).with_lookup(density.lookup);
        build_majorants(&one, extinction[c], bounds, res, bound);
        for (k, &b) in bound.iter().enumerate() {
            channels[3 * k + c] = b;
        }
    }
    for (b, c) in bound.iter_mut().zip(channels.chunks_exact(3)) {
        *b = c[0].max(c[1]).max(c[2]);
    }
}

/// The hero channel of a path: one of the three, uniformly (the balance heuristic's mixture).
#[inline(always)]
pub fn choose_hero(rng: &mut Rng) -> u8 {
    ((rng.next_f32() * 3.0) as u8).min(2)
}

/// Rescales the path densities `r` (mean 1) by an event whose density under channel `c` is
/// proportional to `w_c` (in `[0, 1]`): `r_c <- r_c w_c / mean_j(r_j w_j)`, which keeps the mean 1
/// and every `r_c` in `[0, 3]` (`r_c w_c` is at most the sum). Where the mean is 0 (or NaN) no
/// channel could have sampled the event as the path's hero did, up to underflow: `r` becomes zero
/// and the path, weighing nothing, ends.
#[inline(always)]
pub fn rescale(r: &mut Spectrum, w: Spectrum) {
    let rw = *r * w;
    let mean = (rw.x + rw.y + rw.z) * (1.0 / 3.0);
    *r = if mean > 0.0 {
        rw / mean
    } else {
        Spectrum::ZERO
    };
}

/// Device parameters of a chromatic medium; a grid of length 0 is absent.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ChromaticParams {
    pub density: GridParams,
    pub density_rgb: GridParams,
    pub albedo_grid: GridParams,
    pub majorants: MajorantGridParams,
    pub materials: MaterialGridParams,
    /// Device address of the per-cell channel majorants (three `f32`s a cell), and their count
    /// (0: none).
    pub channel_majorants: u64,
    pub channel_majorants_len: u64,
    pub extinction: [f32; 3],
    pub majorant: f32,
    pub albedo: [f32; 3],
    pub channel_majorant: [f32; 3],
}

fn optional_grid<const C: usize>(
    grid: Option<&Grid<'_, C>>,
    upload: &mut Upload<'_>,
) -> GridParams {
    grid.map_or_else(GridParams::default, |g| {
        GridParams::new(g, upload, GridPlacement::Dense)
    })
}

impl Component for ChromaticMedium<'_> {
    const NAME: &'static str = "chromatic";
    type Params = ChromaticParams;

    fn to_params(&self, upload: &mut Upload<'_>) -> ChromaticParams {
        ChromaticParams {
            density: optional_grid(self.density.as_ref(), upload),
            density_rgb: optional_grid(self.density_rgb.as_ref(), upload),
            albedo_grid: optional_grid(self.albedo_grid.as_ref(), upload),
            majorants: MajorantGridParams::new(self.majorants.as_ref(), upload),
            materials: MaterialGridParams::new(self.materials.as_ref(), upload),
            channel_majorants: self.channel_majorants.map_or(0, |c| upload.values(c)),
            channel_majorants_len: self.channel_majorants.map_or(0, |c| c.len() as u64),
            extinction: self.extinction.to_array(),
            majorant: self.majorant,
            albedo: self.albedo.to_array(),
            channel_majorant: self.channel_majorant.to_array(),
        }
    }

    #[inline]
    unsafe fn from_params(p: &ChromaticParams) -> Self {
        Self {
            extinction: Spectrum::from_array(p.extinction),
            // SAFETY: forwarded to the caller.
            density: (p.density.len > 0).then(|| unsafe { p.density.grid::<1>() }),
            // SAFETY: forwarded to the caller.
            density_rgb: (p.density_rgb.len > 0).then(|| unsafe { p.density_rgb.grid::<3>() }),
            majorant: p.majorant,
            // SAFETY: forwarded to the caller.
            majorants: unsafe { p.majorants.grid() },
            channel_majorant: Spectrum::from_array(p.channel_majorant),
            // SAFETY: forwarded to the caller (the address holds `channel_majorants_len` f32s).
            channel_majorants: (p.channel_majorants_len > 0).then(|| unsafe {
                core::slice::from_raw_parts(
                    p.channel_majorants as *const f32,
                    p.channel_majorants_len as usize,
                )
            }),
            albedo: Spectrum::from_array(p.albedo),
            // SAFETY: forwarded to the caller.
            albedo_grid: (p.albedo_grid.len > 0).then(|| unsafe { p.albedo_grid.grid::<3>() }),
            // SAFETY: forwarded to the caller.
            materials: unsafe { p.materials.grid() },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{rescale, Spectrum};

    /// Where no channel with density left could have sampled the event, `r` becomes zero (the
    /// path ends) instead of 0/0; elsewhere it keeps mean 1 within [0, 3].
    #[test]
    fn rescale_is_zero_where_no_channel_sampled_the_event_and_bounded_elsewhere() {
        let mut r = Spectrum::new(3.0, 0.0, 0.0);
        rescale(&mut r, Spectrum::new(0.0, 1.0, 1.0));
        assert_eq!(r, Spectrum::ZERO);
        let mut r = Spectrum::new(3.0, 0.0, 0.0);
        rescale(&mut r, Spectrum::new(1e-30, 1.0, 1.0));
        assert_eq!(r, Spectrum::new(3.0, 0.0, 0.0));
        let mut r = Spectrum::ONE;
        rescale(&mut r, Spectrum::new(1.0, 0.5, 0.0));
        assert_eq!(r, Spectrum::new(2.0, 1.0, 0.0));
    }
}
