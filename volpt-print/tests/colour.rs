//! Colour conversions and CIEDE2000 against numbers that cannot be tuned: Sharma, Wu and Dalal's
//! published test pairs, exact round trips, and the white point.

use volpt_print::colour::{ciede2000, Lab, LinearRgb, Srgb, Xyz};

/// Sharma, Wu and Dalal 2005, Table 1: the 34 pairs (L*1 a*1 b*1, L*2 a*2 b*2) and their dE00 to
/// four decimals, as the authors publish them with the paper
/// (hajim.rochester.edu/ece/sites/gsharma/ciede2000/dataNprograms/ciede2000testdata.txt). Typed
/// from public copies of that file found with the `code` corpus (query "ciede2000 test data
/// Sharma"): two independent test suites quoting it agree line for line.
const SHARMA_2005_TABLE_1: [[f64; 7]; 34] = [
    [50.0000, 2.6772, -79.7751, 50.0000, 0.0000, -82.7485, 2.0425],
    [50.0000, 3.1571, -77.2803, 50.0000, 0.0000, -82.7485, 2.8615],
    [50.0000, 2.8361, -74.0200, 50.0000, 0.0000, -82.7485, 3.4412],
    [
        50.0000, -1.3802, -84.2814, 50.0000, 0.0000, -82.7485, 1.0000,
    ],
    [
        50.0000, -1.1848, -84.8006, 50.0000, 0.0000, -82.7485, 1.0000,
    ],
    [
        50.0000, -0.9009, -85.5211, 50.0000, 0.0000, -82.7485, 1.0000,
    ],
    [50.0000, 0.0000, 0.0000, 50.0000, -1.0000, 2.0000, 2.3669],
    [50.0000, -1.0000, 2.0000, 50.0000, 0.0000, 0.0000, 2.3669],
    [50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0009, 7.1792],
    [50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0010, 7.1792],
    [50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0011, 7.2195],
    [50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0012, 7.2195],
    [50.0000, -0.0010, 2.4900, 50.0000, 0.0009, -2.4900, 4.8045],
    [50.0000, -0.0010, 2.4900, 50.0000, 0.0010, -2.4900, 4.8045],
    [50.0000, -0.0010, 2.4900, 50.0000, 0.0011, -2.4900, 4.7461],
    [50.0000, 2.5000, 0.0000, 50.0000, 0.0000, -2.5000, 4.3065],
    [50.0000, 2.5000, 0.0000, 73.0000, 25.0000, -18.0000, 27.1492],
    [50.0000, 2.5000, 0.0000, 61.0000, -5.0000, 29.0000, 22.8977],
    [50.0000, 2.5000, 0.0000, 56.0000, -27.0000, -3.0000, 31.9030],
    [50.0000, 2.5000, 0.0000, 58.0000, 24.0000, 15.0000, 19.4535],
    [50.0000, 2.5000, 0.0000, 50.0000, 3.1736, 0.5854, 1.0000],
    [50.0000, 2.5000, 0.0000, 50.0000, 3.2972, 0.0000, 1.0000],
    [50.0000, 2.5000, 0.0000, 50.0000, 1.8634, 0.5757, 1.0000],
    [50.0000, 2.5000, 0.0000, 50.0000, 3.2592, 0.3350, 1.0000],
    [
        60.2574, -34.0099, 36.2677, 60.4626, -34.1751, 39.4387, 1.2644,
    ],
    [
        63.0109, -31.0961, -5.8663, 62.8187, -29.7946, -4.0864, 1.2630,
    ],
    [61.2901, 3.7196, -5.3901, 61.4292, 2.2480, -4.9620, 1.8731],
    [35.0831, -44.1164, 3.7933, 35.0232, -40.0716, 1.5901, 1.8645],
    [
        22.7233, 20.0904, -46.6940, 23.0331, 14.9730, -42.5619, 2.0373,
    ],
    [36.4612, 47.8580, 18.3852, 36.2715, 50.5065, 21.2231, 1.4146],
    [90.8027, -2.0831, 1.4410, 91.1528, -1.6435, 0.0447, 1.4441],
    [90.9257, -0.5406, -0.9208, 88.6381, -0.8985, -0.7239, 1.5381],
    [6.7747, -0.2908, -2.4247, 5.8714, -0.0985, -2.2286, 0.6377],
    [2.0776, 0.0795, -1.1350, 0.9033, -0.0636, -0.5514, 0.9082],
];

fn lab([l, a, b]: [f64; 3]) -> Lab {
    Lab { l, a, b }
}

#[test]
fn ciede2000_matches_sharma_wu_dalal_table_1_both_ways() {
    for (k, row) in SHARMA_2005_TABLE_1.iter().enumerate() {
        let x = lab([row[0], row[1], row[2]]);
        let y = lab([row[3], row[4], row[5]]);
        for (d, order) in [(ciede2000(x, y), "1 to 2"), (ciede2000(y, x), "2 to 1")] {
            // The table rounds to four decimals: half a unit of the last place.
            assert!(
                (d - row[6]).abs() <= 0.5e-4 + 1e-12,
                "pair {} ({order}): dE00 {d:.6}, table {}",
                k + 1,
                row[6]
            );
        }
    }
}

#[test]
fn ciede2000_of_a_colour_with_itself_is_zero() {
    for row in SHARMA_2005_TABLE_1 {
        let x = lab([row[0], row[1], row[2]]);
        assert_eq!(ciede2000(x, x), 0.0);
    }
}

#[test]
fn d65_white_is_lightness_100_without_chroma() {
    let white = LinearRgb([1.0; 3]).to_lab();
    assert!((white.l - 100.0).abs() < 1e-12, "{white:?}");
    assert!(white.a.abs() < 1e-12 && white.b.abs() < 1e-12, "{white:?}");
    // The white is D65 to the matrix's four decimals: x = 0.3127, y = 0.3290.
    let Xyz([x, y, z]) = LinearRgb([1.0; 3]).to_xyz();
    let sum = x + y + z;
    assert!((x / sum - 0.3127).abs() < 1e-4 && (y / sum - 0.3290).abs() < 1e-4);
    assert_eq!(Srgb::from_u8([0; 3]).to_lab().l, 0.0);
}

/// A grid of colours over (and a little outside) the sRGB cube.
fn colours() -> impl Iterator<Item = [f64; 3]> {
    let steps = 12;
    let v = move |i: usize| -0.05 + 1.1 * i as f64 / steps as f64;
    (0..=steps).flat_map(move |r| {
        (0..=steps).flat_map(move |g| (0..=steps).map(move |b| [v(r), v(g), v(b)]))
    })
}

fn assert_close(what: &str, a: [f64; 3], b: [f64; 3], tolerance: f64) {
    for c in 0..3 {
        assert!((a[c] - b[c]).abs() <= tolerance, "{what}: {a:?} vs {b:?}");
    }
}

#[test]
fn conversions_round_trip_to_1e_5() {
    for c in colours() {
        let srgb = Srgb(c);
        assert_close(
            "sRGB -> linear -> sRGB",
            srgb.to_linear().to_srgb().0,
            c,
            1e-5,
        );
        let linear = LinearRgb(c);
        assert_close(
            "linear -> XYZ -> linear",
            linear.to_xyz().to_linear_rgb().0,
            c,
            1e-5,
        );
        let back = linear.to_lab().to_linear_rgb().0;
        assert_close("linear -> Lab -> linear", back, c, 1e-5);
        let lab = linear.to_lab();
        let again = lab.to_xyz().to_lab();
        assert_close(
            "Lab -> XYZ -> Lab",
            [again.l, again.a, again.b],
            [lab.l, lab.a, lab.b],
            1e-5,
        );
    }
    for v in 0..=255u8 {
        let c = [v, 255 - v, v / 3];
        assert_eq!(Srgb::from_u8(c).to_linear().to_srgb().to_u8(), c);
    }
}

#[test]
fn srgb_transfer_function_meets_the_standards_values() {
    // IEC 61966-2-1: 0.5 encoded is 0.21404 linear; the segments meet at 0.04045 / 12.92.
    assert!((Srgb([0.5; 3]).to_linear().0[0] - 0.214041).abs() < 1e-6);
    let knee = Srgb([0.04045; 3]).to_linear().0[0];
    assert!((knee - 0.04045 / 12.92).abs() < 1e-12);
}
