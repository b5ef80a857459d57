//! The dielectric's lobe choice at its edges: reflection is chosen when `u_lobe < F`, so that a
//! uniform `u_lobe` in [0, 1) reflects with probability exactly `F`, also on the random numbers'
//! 2^-24 grid, where `u_lobe = 0` occurs. The statistical tests of `bsdf.rs` cannot see the
//! difference between `<` and `<=` (mutation testing, shard 2/8: it left them green).

use volpt_core::{Bsdf, SmoothDielectric, Vec2, Vec3};

/// An interface between equal indices reflects nothing (`F = 0` exactly at normal incidence), so
/// even the smallest random number, 0, must transmit: with `u_lobe <= F` one path in 2^24 would be
/// mirrored by an interface that is not there.
#[test]
fn an_interface_that_reflects_nothing_transmits_at_u_lobe_zero() {
    let bsdf = SmoothDielectric { eta: 1.0 };
    for n in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
        // Normal incidence from outside (d . n < 0) and from inside (d . n > 0).
        for d in [-n, n] {
            let s = bsdf
                .sample(n, d, 0.0, Vec2::new(0.25, 0.75))
                .expect("normal incidence on a matched interface transmits");
            assert!(s.transmitted, "n = {n}, d = {d}: reflected at F = 0");
            assert_eq!((s.wo, s.weight, s.eta), (d, 1.0, 1.0), "n = {n}, d = {d}");
        }
    }
}
