//! The media as delta and ratio tracking see them: `sigma_t = scale * density`, the albedo of
//! either field, the majorant and the majorant grid a medium hands out, and their device
//! parameters decoded again. The whole-renderer tests see these through images only, and a grid
//! albedo in none of their references.

use volpt_core::abi::Uploader;
use volpt_core::{
    Aabb, Component, ConstantAlbedo, Grid, GridAlbedo, GridMapping, GridMedium, HomogeneousMedium,
    MajorantGrid, Medium, Spectrum, Vec3,
};

fn bounds() -> Aabb {
    Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.5, 4.5))
}

/// Points inside, on the faces of and outside `bounds()`.
fn points() -> Vec<Vec3> {
    let mut points = Vec::new();
    for i in 0..=8 {
        for j in 0..=4 {
            points.push(Vec3::new(
                -1.5 + 0.6 * i as f32,
                -0.3 + 0.45 * j as f32,
                1.8 + 0.37 * (i + 2 * j) as f32 % 3.0,
            ));
        }
    }
    points
}

struct Fields {
    density: Vec<f32>,
    albedo: Vec<f32>,
    majorants: Vec<f32>,
}

const RES: [u32; 3] = [3, 2, 4];

fn fields() -> Fields {
    let n = (RES[0] * RES[1] * RES[2]) as usize;
    Fields {
        density: (0..n).map(|i| 0.5 + ((i * 7) % 5) as f32).collect(),
        albedo: (0..3 * n)
            .map(|i| 0.1 + ((i * 11) % 9) as f32 * 0.1)
            .collect(),
        majorants: vec![11.0, 17.0],
    }
}

fn medium<A>(f: &Fields, albedo: A) -> GridMedium<'_, A> {
    GridMedium {
        density: Grid::new(&f.density, RES, GridMapping::vertex_centred(bounds(), RES)),
        scale: 2.5,
        majorant: 2.5 * 5.5,
        majorants: Some(MajorantGrid::new(&f.majorants, [2, 1, 1], bounds())),
        albedo,
        reads: volpt_core::DenseTrilinear,
    }
}

#[test]
fn grid_media_are_scale_times_density_with_either_albedo() {
    let f = fields();
    let density = Grid::<1>::new(&f.density, RES, GridMapping::vertex_centred(bounds(), RES));
    let albedo_grid = Grid::<3>::new(&f.albedo, RES, GridMapping::cell_centred(bounds(), RES));
    let constant = Spectrum::new(0.3, 0.6, 0.9);
    let with_constant = medium(&f, ConstantAlbedo(constant));
    let with_grid = medium(&f, GridAlbedo(albedo_grid, volpt_core::DenseTrilinear));
    let mut varied = false;
    for p in points() {
        let sigma_t = 2.5 * density.lookup(p)[0];
        assert_eq!(with_constant.sigma_t(p), sigma_t, "at {p}");
        assert_eq!(with_grid.sigma_t(p), sigma_t, "at {p}");
        assert_eq!(with_constant.albedo(p), constant, "at {p}");
        let expected = Spectrum::from_array(albedo_grid.lookup(p));
        assert_eq!(with_grid.albedo(p), expected, "at {p}");
        varied |= expected != Spectrum::ZERO && expected.x != expected.y;
    }
    assert!(varied, "the albedo grid is not seen");
    for m in [with_constant.majorant(), with_grid.majorant()] {
        assert_eq!(m, 2.5 * 5.5);
    }
    let grid = with_grid
        .majorant_grid()
        .expect("the medium's majorant grid");
    assert_eq!((grid.data, grid.res), (&f.majorants[..], [2, 1, 1]));
    assert!(with_constant.majorant_grid().is_some());
    let without = GridMedium {
        majorants: None,
        ..with_constant
    };
    assert!(without.majorant_grid().is_none());
}

#[test]
fn a_homogeneous_medium_is_the_same_everywhere() {
    let m = HomogeneousMedium {
        sigma_t: 3.25,
        albedo: Spectrum::new(0.2, 0.4, 0.8),
    };
    for p in points() {
        assert_eq!(m.sigma_t(p), 3.25);
        assert_eq!(m.albedo(p), Spectrum::new(0.2, 0.4, 0.8));
    }
    assert_eq!(m.majorant(), 3.25);
    assert!(m.majorant_grid().is_none());
}

/// "Uploads" by leaving the values where they are, as a host uploader does.
struct InPlace;

impl Uploader for InPlace {
    fn values(&mut self, values: &[f32]) -> u64 {
        values.as_ptr() as u64
    }
}

#[test]
fn media_survive_the_device_encoding() {
    let f = fields();
    let albedo_grid = Grid::<3>::new(&f.albedo, RES, GridMapping::cell_centred(bounds(), RES));
    let constant = ConstantAlbedo(Spectrum::new(0.3, 0.6, 0.9));

    let m = medium(&f, constant);
    // SAFETY: every address is a slice of `f`, alive for the whole test.
    let decoded = unsafe { GridMedium::<ConstantAlbedo>::from_params(&m.to_params(&mut InPlace)) };
    let m2 = medium(&f, GridAlbedo(albedo_grid, volpt_core::DenseTrilinear));
    // SAFETY: as above.
    let decoded2 = unsafe { GridMedium::<GridAlbedo>::from_params(&m2.to_params(&mut InPlace)) };
    for p in points() {
        assert_eq!(decoded.sigma_t(p), m.sigma_t(p), "at {p}");
        assert_eq!(decoded.albedo(p), m.albedo(p), "at {p}");
        assert_eq!(decoded2.sigma_t(p), m2.sigma_t(p), "at {p}");
        assert_eq!(decoded2.albedo(p), m2.albedo(p), "at {p}");
    }
    assert_eq!(decoded.majorant(), m.majorant());
    assert_eq!(decoded.scale, m.scale);
    let grid = decoded.majorant_grid().expect("the majorant grid travels");
    assert_eq!(
        (grid.data, grid.res, grid.bounds),
        (&f.majorants[..], [2, 1, 1], bounds())
    );

    let h = HomogeneousMedium {
        sigma_t: 3.25,
        albedo: Spectrum::new(0.2, 0.4, 0.8),
    };
    // SAFETY: a homogeneous medium's parameters hold no address.
    let decoded = unsafe { HomogeneousMedium::from_params(&h.to_params(&mut InPlace)) };
    assert_eq!((decoded.sigma_t, decoded.albedo), (h.sigma_t, h.albedo));
}
