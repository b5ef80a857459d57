//! A voxel print: one material index per voxel and the material table the indices name.
//!
//! Voxel `(x, y, z)` is `indices[x + width * (y + height * z)]`; layer `z = 0` is the bottom,
//! printed first (`slice_0000.png`), and the top surface, seen from +z, is layer `depth - 1`.
//! Surface texel `(x, y)` is the column of voxels `(x, y, *)`.

use volpt_scene::material::MaterialDesc;

#[derive(Clone, Debug, PartialEq)]
pub struct VoxelPrint {
    materials: Vec<MaterialDesc>,
    /// Voxel size (x, y, layer height), in the units the materials' coefficients are per.
    voxel_size: [f64; 3],
    resolution: [u32; 3],
    indices: Vec<u8>,
}

/// Why the parts given to [`VoxelPrint::new`] are not a print: `(field, expected, found)`.
pub type Problem = (&'static str, String, String);

impl VoxelPrint {
    /// A print from its parts, checked: every index names a material, the grid has the
    /// resolution's voxel count, sizes are positive and finite, and palette colours are distinct.
    pub fn new(
        materials: Vec<MaterialDesc>,
        voxel_size: [f64; 3],
        resolution: [u32; 3],
        indices: Vec<u8>,
    ) -> Result<VoxelPrint, Problem> {
        check_table(&materials)?;
        if !voxel_size.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err((
                "voxel_size",
                "three finite sizes > 0".into(),
                format!("{voxel_size:?}"),
            ));
        }
        let voxels = resolution
            .iter()
            .try_fold(1usize, |a, &n| a.checked_mul(n as usize));
        if resolution.contains(&0) || voxels != Some(indices.len()) {
            return Err((
                "indices",
                format!("one per voxel of {resolution:?}, no axis empty"),
                indices.len().to_string(),
            ));
        }
        if let Some(k) = indices
            .iter()
            .position(|&i| usize::from(i) >= materials.len())
        {
            return Err((
                "indices",
                format!("material indices below {}", materials.len()),
                format!("{} at voxel {k}", indices[k]),
            ));
        }
        Ok(VoxelPrint {
            materials,
            voxel_size,
            resolution,
            indices,
        })
    }

    pub fn materials(&self) -> &[MaterialDesc] {
        &self.materials
    }

    pub fn voxel_size(&self) -> [f64; 3] {
        self.voxel_size
    }

    /// Width (x), height (y) and depth (layers, z).
    pub fn resolution(&self) -> [u32; 3] {
        self.resolution
    }

    /// Every voxel's material index, x fastest, then y, then z (bottom layer first).
    pub fn indices(&self) -> &[u8] {
        &self.indices
    }

    /// The material index of voxel `(x, y, z)`.
    pub fn at(&self, x: u32, y: u32, z: u32) -> u8 {
        let [w, h, _] = self.resolution.map(|n| n as usize);
        self.indices[x as usize + w * (y as usize + h * z as usize)]
    }

    /// Layer `z`'s indices (row-major, `width * height`).
    pub fn layer(&self, z: u32) -> &[u8] {
        let n = self.resolution[0] as usize * self.resolution[1] as usize;
        &self.indices[n * z as usize..n * (z as usize + 1)]
    }
}

/// Checks a print's material table: 1 to 256 materials (an index is a byte: a print's inks are a
/// handful), each with a palette colour, the colours distinct. Each material's numbers are
/// volpt-scene's to check (its reader, and [`MaterialDesc::problem`] where a scene is built).
pub fn check_table(materials: &[MaterialDesc]) -> Result<(), Problem> {
    if materials.is_empty() || materials.len() > usize::from(u8::MAX) + 1 {
        return Err((
            "materials",
            "1 to 256 materials".into(),
            materials.len().to_string(),
        ));
    }
    for (k, m) in materials.iter().enumerate() {
        if m.colour.is_none() {
            return Err((
                "materials.colour",
                "a palette colour per material".into(),
                format!("none for {}", m.name),
            ));
        }
        if let Some(j) = materials[..k].iter().position(|o| o.colour == m.colour) {
            return Err((
                "materials.colour",
                "a palette colour per material, each distinct".into(),
                format!(
                    "{:?} for both {} and {}",
                    m.colour.unwrap_or_default(),
                    materials[j].name,
                    m.name
                ),
            ));
        }
    }
    Ok(())
}
