//! The noise floor of a prediction's CIEDE2000 at a sample count: a uniform print (every texel
//! aiming at one colour, white by default) predicted by volpt on the CPU, measured three ways.
//!
//! ```sh
//! cargo run --release -p volpt-print --example floor -- M.toml SIZE LAYERS COLOUR_LAYERS SPP [R G B]
//! ```
//!
//! - **texel mean**: the mean linear RGB over the print's texels (a low-noise estimate of what a
//!   texel away from the edges shows) and its CIEDE2000 from the aimed colour: what the inks can
//!   do, not noise;
//! - **against the aim**: the mean over texels of each texel's CIEDE2000 from the aimed colour
//!   (what a compensation's record reports for this print);
//! - **noise floor**: the mean over texels of the CIEDE2000 between two independent predictions,
//!   over sqrt 2 (their difference has twice one's variance; where the noise is small a colour
//!   difference is a norm of it, so this is the mean CIEDE2000 of one prediction from its own
//!   expectation: what a texel predicted exactly right still shows), and the loop's own noise
//!   measure (one standard error moved).

use volpt::Backend;
use volpt_print::colour::{ciede2000, LinearRgb, Srgb};
use volpt_print::compensate::{noise, print_for, Predictor, Setup};
use volpt_print::halftone::Halftone;
use volpt_print::predict::RenderPredictor;
use volpt_print::{Inks, MaterialFile};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some([materials, size, layers, colour_layers, spp]) = args.first_chunk::<5>() else {
        return Err("expected M.toml SIZE LAYERS COLOUR_LAYERS SPP [R G B]".into());
    };
    let rgb: Vec<u8> = args[5..]
        .iter()
        .map(|v| v.parse())
        .collect::<Result<_, _>>()?;
    let aim = Srgb::from_u8(rgb.try_into().unwrap_or([255; 3])).to_linear();
    let table = MaterialFile::read(materials.as_ref())?;
    let n: u32 = size.parse()?;
    let setup = Setup {
        halftone: Halftone {
            layers: colour_layers.parse()?,
            depth: layers.parse()?,
            inks: Inks::find(&table.materials)?,
            seed: 0,
        },
        voxel_size: table.voxel_size.unwrap_or(volpt_print::job::VOXEL_SIZE),
        materials: table.materials,
    };
    let print =
        print_for(&setup, &vec![aim; (n * n) as usize], n, n).map_err(|e| format!("{e:?}"))?;
    let backend = Backend::cpu();
    let spp: u32 = spp.parse()?;
    let mut predictor = RenderPredictor::new(&backend, spp);
    let start = std::time::Instant::now();
    let p = predictor.predict(&print)?;
    let e = predictor.standard_error().unwrap_or_default().to_vec();
    // A second, independent prediction (the halves take seeds `seed` and `seed + 1`).
    predictor.seed = 2;
    let q = predictor.predict(&print)?;
    let texels = p.len() as f64;
    let mean = LinearRgb([0, 1, 2].map(|c| p.iter().map(|t| t.0[c]).sum::<f64>() / texels));
    let aim_lab = aim.to_lab();
    let mean_de = |a: &[LinearRgb], f: &dyn Fn(usize) -> LinearRgb| {
        a.iter()
            .enumerate()
            .map(|(i, t)| ciede2000(t.to_lab(), f(i).to_lab()))
            .sum::<f64>()
            / texels
    };
    let against = mean_de(&p, &|_| aim);
    let floor = mean_de(&p, &|i| q[i]) / std::f64::consts::SQRT_2;
    println!(
        "{n} x {n} x {layers} ({colour_layers} colour), aim sRGB {:?}, {spp} spp, {:.1} s:\n  \
         texel mean linear {:.4?} (sRGB {:?}), its dE00 from the aim {:.3}\n  \
         mean dE00 against the aim {against:.3}\n  \
         noise floor (two predictions' mean dE00 / sqrt 2) {floor:.3}; \
         the loop's noise (one standard error's dE00) {:.3}",
        aim.to_srgb().to_u8(),
        start.elapsed().as_secs_f64(),
        mean.0,
        mean.to_srgb().to_u8(),
        ciede2000(mean.to_lab(), aim_lab),
        noise(&p, &e),
    );
    Ok(())
}
