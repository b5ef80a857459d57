//! Mitsuba 0.6's medium `material` presets, the table as Mitsuba 0.6 ships it
//! (`src/medium/materials.h` of mitsuba-renderer/mitsuba): Jensen et al. 2001, "A Practical Model
//! for Subsurface Light Transport" (their measured reduced scattering and absorption
//! coefficients, in mm^-1), then Narasimhan et al. 2006, "Acquiring Scattering Properties of
//! Participating Media by Dilution". Mitsuba multiplies both by 100 (its unit convention for the
//! presets) and then by the medium's `scale`; volpt does the same, so a scene renders the
//! extinction Mitsuba renders. Names match case-insensitively, as in Mitsuba.
//!
//! Mitsuba's table also carries per-channel phase asymmetries and indices of refraction, which its
//! subsurface (dipole) plugins read; a `<medium>`'s phase function is its own `<phase>` child, so
//! volpt reads the preset's `sigmaS` and `sigmaA` alone.

/// `(name, sigmaS, sigmaA)` of every preset, as the table lists them (before the factor 100).
pub const PRESETS: &[(&str, [f32; 3], [f32; 3])] = &[
    ("Apple", [2.29, 2.39, 1.97], [0.0030, 0.0034, 0.046]),
    ("Chicken1", [0.15, 0.21, 0.38], [0.0015, 0.077, 0.19]),
    ("Chicken2", [0.19, 0.25, 0.32], [0.0018, 0.088, 0.20]),
    ("Cream", [7.38, 5.47, 3.15], [0.0002, 0.0028, 0.0163]),
    ("Ketchup", [0.18, 0.07, 0.03], [0.061, 0.97, 1.45]),
    ("Marble", [2.19, 2.62, 3.00], [0.0021, 0.0041, 0.0071]),
    ("Potato", [0.68, 0.70, 0.55], [0.0024, 0.0090, 0.12]),
    ("Skimmilk", [0.70, 1.22, 1.90], [0.0014, 0.0025, 0.0142]),
    ("Skin1", [0.74, 0.88, 1.01], [0.032, 0.17, 0.48]),
    ("Skin2", [1.09, 1.59, 1.79], [0.013, 0.070, 0.145]),
    ("Spectralon", [11.6, 20.4, 14.9], [0.00, 0.00, 0.00]),
    ("Wholemilk", [2.55, 3.21, 3.77], [0.0011, 0.0024, 0.014]),
    (
        "Lowfat Milk",
        [13.1157, 15.4445, 17.9572],
        [0.00287, 0.00575, 0.01150],
    ),
    (
        "Reduced Milk",
        [13.7335, 15.6003, 17.8007],
        [0.00256, 0.00511, 0.01278],
    ),
    (
        "Regular Milk",
        [18.2052, 20.3826, 22.3698],
        [0.00153, 0.00460, 0.01993],
    ),
    (
        "Espresso",
        [7.78262, 8.13050, 8.53875],
        [4.79838, 6.57512, 8.84925],
    ),
    (
        "Mint Mocha Coffee",
        [3.51133, 4.14383, 5.59667],
        [3.77200, 5.82283, 7.82000],
    ),
    (
        "Lowfat Soy Milk",
        [2.03838, 2.32875, 3.90281],
        [0.00144, 0.00719, 0.03594],
    ),
    (
        "Regular Soy Milk",
        [4.66325, 5.20183, 8.74575],
        [0.00192, 0.00958, 0.06517],
    ),
    (
        "Lowfat Chocolate Milk",
        [9.83710, 11.4954, 13.1629],
        [0.01150, 0.03680, 0.15640],
    ),
    (
        "Regular Chocolate Milk",
        [10.5685, 13.1416, 15.2202],
        [0.01006, 0.04313, 0.14375],
    ),
    (
        "Coke",
        [0.00254, 0.00299, 0.00000],
        [0.10014, 0.16503, 0.24680],
    ),
    (
        "Pepsi",
        [0.00083, 0.00203, 0.00000],
        [0.09164, 0.14158, 0.20729],
    ),
    (
        "Sprite",
        [0.00011, 0.00014, 0.00014],
        [0.00189, 0.00183, 0.00200],
    ),
    (
        "Gatorade",
        [0.03668, 0.04488, 0.05742],
        [0.02479, 0.01929, 0.00888],
    ),
    (
        "Chardonnay",
        [0.00021, 0.00033, 0.00048],
        [0.01078, 0.01186, 0.02400],
    ),
    (
        "White Zinfandel",
        [0.00022, 0.00033, 0.00046],
        [0.01207, 0.01618, 0.01984],
    ),
    (
        "Merlot",
        [0.00081, 0.00000, 0.00000],
        [0.11632, 0.25191, 0.29434],
    ),
    (
        "Budweiser Beder",
        [0.00029, 0.00055, 0.00059],
        [0.01149, 0.02491, 0.05779],
    ),
    (
        "Coors Light Beer",
        [0.00062, 0.00127, 0.00000],
        [0.00616, 0.01398, 0.03498],
    ),
    (
        "Clorox",
        [0.02731, 0.03302, 0.03695],
        [0.00335, 0.01489, 0.02630],
    ),
    (
        "Apple Juice",
        [0.00257, 0.00311, 0.00413],
        [0.01296, 0.02374, 0.05218],
    ),
    (
        "Cranberry Juice",
        [0.00196, 0.00238, 0.00301],
        [0.03944, 0.09422, 0.12426],
    ),
    (
        "Grape Juice",
        [0.00138, 0.00000, 0.00000],
        [0.10404, 0.23958, 0.29325],
    ),
    (
        "Ruby Grapefruit Juice",
        [0.15496, 0.15391, 0.15995],
        [0.08587, 0.18314, 0.25262],
    ),
    (
        "White Grapefruit Juice",
        [0.50499, 0.52742, 0.75282],
        [0.01380, 0.01883, 0.05678],
    ),
    (
        "Shampoo",
        [0.00797, 0.00874, 0.01127],
        [0.01411, 0.04569, 0.06172],
    ),
    (
        "Strawberry Shampoo",
        [0.00215, 0.00245, 0.00253],
        [0.01449, 0.05796, 0.07582],
    ),
    (
        "Head & Shoulders Shampoo",
        [0.26747, 0.27696, 0.29574],
        [0.08462, 0.15688, 0.20365],
    ),
    (
        "Lemon Tea Powder",
        [0.74489, 0.83823, 1.00158],
        [2.42881, 4.57573, 7.21270],
    ),
    (
        "Orange Juice Powder",
        [0.00193, 0.00213, 0.00226],
        [0.00145, 0.00344, 0.00786],
    ),
    (
        "Pink Lemonade Powder",
        [0.00123, 0.00133, 0.00131],
        [0.00116, 0.00237, 0.00320],
    ),
    (
        "Cappuccino Powder",
        [12.2094, 16.4659, 29.2727],
        [35.8441, 49.5470, 61.0844],
    ),
    (
        "Salt Powder",
        [0.13805, 0.15677, 0.17865],
        [0.28415, 0.32570, 0.34148],
    ),
    (
        "Sugar Powder",
        [0.00282, 0.00315, 0.00393],
        [0.01264, 0.03105, 0.05012],
    ),
    (
        "Suisse Mocha Powder",
        [30.0848, 33.4452, 38.7191],
        [17.5020, 27.0044, 35.4334],
    ),
    (
        "Pacific Ocean Surface Water",
        [0.00180, 0.00183, 0.00228],
        [0.03184, 0.03132, 0.03015],
    ),
];

/// Mitsuba's factor from the table's numbers to a preset's coefficients.
pub const PRESET_UNIT: f32 = 100.0;

/// The preset Mitsuba 0.6 falls back to where a medium gives no coefficients.
pub const DEFAULT_PRESET: &str = "Skin1";

/// The scattering and absorption coefficients of preset `name` (any case), with Mitsuba's factor.
pub fn preset(name: &str) -> Option<([f32; 3], [f32; 3])> {
    PRESETS
        .iter()
        .find(|(n, _, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, s, a)| (s.map(|v| v * PRESET_UNIT), a.map(|v| v * PRESET_UNIT)))
}

/// The presets' names, for an error that lists them.
pub fn preset_names() -> String {
    PRESETS
        .iter()
        .map(|(n, _, _)| *n)
        .collect::<Vec<_>>()
        .join(", ")
}
