//! A small scene with a density grid and an RGB albedo grid, written to files: what the tests of
//! replaceable grids load fresh and compare with a scene whose grids were replaced.

use std::path::{Path, PathBuf};

use volpt::scene_files::{write_vol, Bounds, VolGrid};

/// The grids' resolution.
const RES: [u32; 3] = [6, 5, 4];

/// A density grid: a ball of density `peak` at the centre falling off to the box's corners.
pub fn density(peak: f32) -> Vec<f32> {
    let [nx, ny, nz] = RES.map(|n| n as usize);
    let mut values = Vec::with_capacity(nx * ny * nz);
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let d = [(x, nx), (y, ny), (z, nz)]
                    .map(|(i, n)| (i as f32 + 0.5) / n as f32 - 0.5)
                    .iter()
                    .map(|c| c * c)
                    .sum::<f32>();
                values.push(peak * (1.0 - 1.5 * d).max(0.0));
            }
        }
    }
    values
}

/// An RGB albedo grid: a gradient along x, its colour turned by `turn`.
pub fn albedo(turn: f32) -> Vec<f32> {
    let count = RES.iter().product::<u32>() as usize;
    (0..count)
        .flat_map(|i| {
            let t = (i % RES[0] as usize) as f32 / RES[0] as f32;
            [0.9 - 0.5 * t, 0.3 + 0.6 * t * turn, 0.6]
        })
        .collect()
}

/// A Mitsuba scene with a density grid and an RGB albedo grid holding `density` and `albedo`,
/// written to files in `dir`.
pub fn scene_file(dir: &Path, density: &[f32], albedo: &[f32]) -> PathBuf {
    let bbox = Bounds {
        min: [-0.5; 3],
        max: [0.5; 3],
    };
    for (name, channels, data) in [("density", 1, density), ("albedo", 3, albedo)] {
        let grid = VolGrid {
            resolution: RES,
            channels,
            bbox,
            data: data.to_vec(),
        };
        write_vol(&dir.join(format!("{name}.vol")), &grid).unwrap();
    }
    let xml = r#"<scene version="0.6.0">
    <integrator type="volpath"><integer name="maxDepth" value="-1"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="toWorld"><lookat origin="2, 1.5, 2.5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sampleCount" value="4"/></sampler>
        <film type="hdrfilm"><integer name="width" value="10"/><integer name="height" value="8"/></film>
    </sensor>
    <emitter type="constant"><spectrum name="radiance" value="1"/></emitter>
    <medium type="heterogeneous" id="m">
        <volume name="density" type="gridvolume"><string name="filename" value="density.vol"/></volume>
        <volume name="albedo" type="gridvolume"><string name="filename" value="albedo.vol"/></volume>
        <float name="scale" value="6"/>
        <phase type="hg"><float name="g" value="0.3"/></phase>
    </medium>
    <shape type="cube"><bsdf type="null"/><transform name="toWorld"><scale value="0.5"/></transform><ref name="interior" id="m"/></shape>
</scene>"#;
    let path = dir.join("scene.xml");
    std::fs::write(&path, xml).unwrap();
    path
}
