//! A target's regions (where an error lies): classed by the Chebyshev distance to the nearest
//! ink texel, and their means.

use volpt_print::colour::LinearRgb;
use volpt_print::regions::{region_means, regions, Region, EDGE, NEAR};

#[test]
fn each_white_texel_is_classed_by_its_distance_to_the_nearest_ink() {
    // Two ink texels on a 23 x 17 white target; every texel's class against its distance
    // computed over the whole target (no window).
    let [w, h] = [23usize, 17];
    let ink = [(3usize, 4usize), (15, 12)];
    let target: Vec<LinearRgb> = (0..w * h)
        .map(|i| match ink.contains(&(i % w, i / w)) {
            true => LinearRgb([0.2, 0.99, 0.99]),
            false => LinearRgb([1.0; 3]),
        })
        .collect();
    let classes = regions(&target, [w as u32, h as u32]);
    let mut seen = [0; 4];
    for (i, class) in classes.iter().enumerate() {
        let (x, y) = (i % w, i / w);
        let d = ink
            .iter()
            .map(|&(a, b)| a.abs_diff(x).max(b.abs_diff(y)))
            .min()
            .unwrap();
        let expected = match d {
            0 => Region::Ink,
            d if d <= EDGE => Region::Edge,
            d if d <= NEAR => Region::Near,
            _ => Region::Far,
        };
        assert_eq!(*class, expected, "texel ({x}, {y}) at distance {d}");
        seen[class.index()] += 1;
    }
    assert!(
        seen.iter().all(|&n| n > 0),
        "every region present: {seen:?}"
    );
    // A white target has no ink and nothing near it.
    let white = vec![LinearRgb([1.0; 3]); w * h];
    assert!(regions(&white, [w as u32, h as u32])
        .iter()
        .all(|&r| r == Region::Far));
}

#[test]
fn region_means_are_each_region_s_mean_and_share() {
    let classes = [Region::Ink, Region::Edge, Region::Edge, Region::Far];
    let values = [4.0, 1.0, 3.0, 10.0];
    let means = region_means(&values, &classes);
    assert_eq!(means[0], (0.25, Some(4.0)));
    assert_eq!(means[1], (0.5, Some(2.0)));
    assert_eq!(means[2], (0.0, None));
    assert_eq!(means[3], (0.25, Some(10.0)));
}
