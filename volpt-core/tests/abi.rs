//! The device ABI's host side with a closure as the uploader, as the CUDA backend uses it (a copy to
//! device memory returning its address): the parameters carry the addresses the closure returned,
//! in the order the parts were uploaded, and the lengths of what it was given. The whole-renderer
//! round trip (`tests/tests/device_abi.rs`) uses an uploader type of its own, so it never calls the
//! blanket implementation for closures or the default dense `Uploader::grid`.

use volpt_core::abi::{GridParams, Uploader};
use volpt_core::{
    Aabb, Component, ConstantEnvironment, Grid, GridLayout, GridMapping, LatLongEnvironment,
    LatLongRows, Vec3,
};

/// A closure uploader that hands out made-up device addresses and records what it was given.
fn recording(calls: &mut Vec<Vec<f32>>) -> impl FnMut(&[f32]) -> u64 + '_ {
    move |values: &[f32]| {
        calls.push(values.to_vec());
        0x1000 * calls.len() as u64 + 8
    }
}

#[test]
fn a_closure_uploads_a_dense_grid_and_its_address_is_kept() {
    let data: Vec<f32> = (0..24).map(|i| i as f32 * 0.5).collect();
    let res = [2, 3, 4];
    let bounds = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.5, 4.5));
    let grid: Grid<'_, 1> = Grid::new(&data, res, GridMapping::vertex_centred(bounds, res));
    let mut calls = Vec::new();
    let params = {
        let mut upload = recording(&mut calls);
        assert_eq!(Uploader::values(&mut upload, &[1.0, 2.0]), 0x1008);
        GridParams::new(&grid, &mut upload)
    };
    assert_eq!(calls, vec![vec![1.0, 2.0], data.clone()]);
    assert_eq!(params.data, 0x2008, "the address the closure returned");
    assert_eq!(params.len, 24);
    assert_eq!(params.layout, GridLayout::Dense.to_u32());
    assert_eq!(params.res, res);
    assert_eq!(params.channels, 1);
}

#[test]
fn a_closure_uploads_a_lat_long_map_and_its_distribution() {
    let (width, height) = (3, 2);
    let rgb: Vec<f32> = (0..3 * width * height).map(|i| 0.1 + i as f32).collect();
    let rotation = [Vec3::X, Vec3::Y, Vec3::Z];
    let map = LatLongEnvironment::new(&rgb, width, height, LatLongRows::PoleToPole, rotation, 2.0);
    let mut distribution = vec![0.0; LatLongEnvironment::distribution_len(width, height)];
    map.fill_distribution(&mut distribution);
    let map = LatLongEnvironment {
        distribution: &distribution,
        ..map
    };
    let mut calls = Vec::new();
    let params = map.to_params(&mut recording(&mut calls));
    assert_eq!(calls, vec![rgb.clone(), distribution.clone()]);
    assert_eq!((params.texels, params.len), (0x1008, rgb.len() as u64));
    assert_eq!(
        (params.distribution, params.distribution_len),
        (0x2008, distribution.len() as u64)
    );
    assert_eq!((params.width, params.height, params.scale), (3, 2, 2.0));
}

#[test]
fn a_constant_environment_travels_as_its_radiance() {
    let env = ConstantEnvironment(Vec3::new(0.25, 1.5, 3.0));
    let mut calls = Vec::new();
    let params = env.to_params(&mut recording(&mut calls));
    assert!(calls.is_empty(), "a constant uploads nothing");
    assert_eq!(params.radiance, [0.25, 1.5, 3.0]);
    // SAFETY: a constant's parameters hold no address.
    let decoded = unsafe { ConstantEnvironment::from_params(&params) };
    assert_eq!(decoded.0, env.0);
}
