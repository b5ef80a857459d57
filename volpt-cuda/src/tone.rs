//! The viewer's frames tone mapped on the GPU from the film a render left there
//! ([`volpt_device::tone`]): the frame's 8-bit bytes are all that comes back, instead of its
//! `f64` sums for the CPU to tone map.

use cudarc::driver::{CudaSlice, LaunchConfig, PushKernelArg};
use volpt_device::launch::BLOCK_SIZE;

use crate::error::{CudaError, Doing};
use crate::renderer::FilmHeld;
use crate::CudaRenderer;

impl CudaRenderer {
    /// The frame of the film the last render left on this GPU over `spp` samples at
    /// 2^`exposure`: 8-bit sRGB RGB, row-major from the top-left pixel, as
    /// `volpt_film::tone::tone_map` of the film's image gives it within one level. The film is
    /// that of a finished render of samples `0..spp` of a `size` image, or that of a render in
    /// flight ([`CudaRenderer::render_samples_until`]) whose range ends at `spp`; `None` where
    /// the GPU holds neither (no render yet, another size or range since, a batch of several
    /// GPUs).
    pub fn tone_map_film(
        &self,
        size: (u32, u32),
        spp: u32,
        exposure: f32,
    ) -> Result<Option<Vec<u8>>, CudaError> {
        // The order `render_samples_until` takes them in.
        let in_flight = self.in_flight.lock().unwrap_or_else(|e| e.into_inner());
        let buffers = self.buffers.lock().unwrap_or_else(|e| e.into_inner());
        let finished = buffers
            .as_ref()
            .filter(|b| b.holds == Some(FilmHeld { size, spp }))
            .map(|b| &b.film);
        let Some(film) = finished.or_else(|| in_flight.as_ref()?.film_over(size, spp)) else {
            return Ok(None);
        };
        let pixels = size.0 * size.1;
        let mut frame = self.frame.lock().unwrap_or_else(|e| e.into_inner());
        let frame = match frame.take() {
            Some(f) if f.len() == 3 * pixels as usize => frame.insert(f),
            _ => frame.insert(
                self.stream()
                    .alloc_zeros(3 * pixels as usize)
                    .doing("allocating the frame")?,
            ),
        };
        self.launch_tone_map(film, frame, pixels, spp, exposure)?;
        let bytes = self.stream().clone_dtoh(frame).doing("reading the frame")?;
        Ok(Some(bytes))
    }

    /// Launches the tone-mapping kernel: `frame` gets the frame of the first `pixels` pixels of
    /// `film` (sums of `spp` samples) at 2^`exposure`.
    pub(crate) fn launch_tone_map(
        &self,
        film: &CudaSlice<f64>,
        frame: &mut CudaSlice<u8>,
        pixels: u32,
        spp: u32,
        exposure: f32,
    ) -> Result<(), CudaError> {
        assert!(
            film.len() >= 3 * pixels as usize && frame.len() >= 3 * pixels as usize,
            "a film and a frame of {pixels} pixels"
        );
        let kernel = self.kernel(volpt_device::tone::ENTRIES[0], None)?;
        let config = LaunchConfig {
            grid_dim: (pixels.div_ceil(BLOCK_SIZE).max(1), 1, 1),
            block_dim: (BLOCK_SIZE, 1, 1),
            shared_mem_bytes: 0,
        };
        let inv_spp = 1.0 / f64::from(spp);
        let gain = exposure.exp2();
        // SAFETY: `film` holds three sums and `frame` three bytes for each of `pixels` pixels
        // (asserted above), both alive until the launch has been waited for (`clone_dtoh`).
        unsafe {
            self.stream()
                .launch_builder(&kernel)
                .arg(film)
                .arg(frame)
                .arg(&pixels)
                .arg(&inv_spp)
                .arg(&gain)
                .launch(config)
        }
        .doing("launching the tone mapping")?;
        Ok(())
    }
}
