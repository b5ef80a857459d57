//! The viewer's frame tone mapped on the GPU equals the CPU's within one 8-bit level: first the
//! per-pixel function the kernel runs (`volpt_device::tone`), run here on the CPU, against the
//! CPU's table (`volpt_film::tone`), on every machine; then the kernel itself where a GPU and
//! kernels are present (skipped, saying so, elsewhere; `volpt selftest --backend cuda` runs the
//! same check from the binary).

use volpt_cuda::selftest::tone::{check, cpu_frame, film, EXPOSURES};
use volpt_cuda::{CudaError, CudaRenderer, Math};
use volpt_device::tone::tone_map_pixel;

#[test]
fn the_kernels_pixel_function_is_the_cpus_frame_within_one_level() {
    let spp = 7;
    let film = film(1 << 16, spp);
    for exposure in EXPOSURES {
        let reference: Vec<u8> = film
            .sums
            .iter()
            .flat_map(|&sum| tone_map_pixel(sum, 1.0 / f64::from(spp), exposure.exp2()))
            .collect();
        let (failures, measured) = check(
            &cpu_frame(&film, spp, exposure),
            &reference,
            &format!("exposure {exposure}"),
        );
        eprintln!("{measured}");
        assert!(
            failures.is_empty(),
            "{:?}",
            &failures[..failures.len().min(5)]
        );
    }
}

#[test]
fn the_gpus_frame_is_the_cpus_within_one_level() {
    for math in Math::ALL.iter().copied() {
        let renderer = match CudaRenderer::new(0, math) {
            Ok(renderer) => renderer,
            Err(e @ (CudaError::NoDriver | CudaError::NoKernels(_) | CudaError::Driver { .. })) => {
                eprintln!("SKIPPED ({math} kernels): {e}");
                continue;
            }
            Err(e) => panic!("{math}: {e}"),
        };
        let test = renderer.tone_mapping().unwrap();
        eprintln!("{math}: {}", test.measured);
        assert!(
            test.failures.is_empty(),
            "{math}: {:?}",
            &test.failures[..test.failures.len().min(5)]
        );
    }
}
