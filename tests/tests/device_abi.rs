//! The device ABI round trip: every variant of the registry, written into its launch parameters by
//! the host code (`SceneAbi::to_params`) and rebuilt by the device code (`SceneAbi::from_params`),
//! renders bit-identically to the scene it came from. The "device addresses" are the host's own
//! slices, so this runs on any machine and exercises exactly the code a kernel runs.
//!
//! A swapped field in a part's parameters (a grid's scale and offset, say) changes the image and
//! fails here, although CI has no GPU.

use std::collections::BTreeSet;

use volpt_core::abi::{PlacedGrid, Uploader};
use volpt_core::{
    AnyLayout, Component, GridLayout, GridPlacement, GridReads, HomogeneousMedium, SceneAbi,
    TexelFormat,
};
use volpt_render::{render, with_scene, Image, RenderOptions, RenderScene, SceneVisitor, Variant};
use volpt_scene::description::*;
use volpt_tests::cube_scene;

/// A description of every combination of the axes the factory reads: every example of each.
fn descriptions() -> Vec<SceneDescription> {
    // Every axis's examples, from its file in volpt-scene: a new kind's example there is covered
    // here.
    let media = MediumDesc::examples();
    let boundaries = BsdfDesc::examples();
    let phases = PhaseDesc::examples();
    let environments = EnvironmentDesc::examples();
    let mut descs = Vec::new();
    for medium in &media {
        for &bsdf in &boundaries {
            for &phase in &phases {
                for environment in &environments {
                    let medium = MediumDesc {
                        phase,
                        ..medium.clone()
                    };
                    let mut desc = cube_scene(12, 9, medium, bsdf, 1.0);
                    desc.environment = environment.clone();
                    desc.integrator.rr_depth = Some(3);
                    descs.push(desc);
                }
            }
        }
    }
    descs
}

/// "Uploads" to the host itself: values stay where they are, grids in the bricked layout and
/// sparse grids' flat copies are written into buffers it keeps, as the CUDA backend's placer
/// does in device or pinned memory.
struct HostUploader {
    layout: GridLayout,
    buffers: Vec<Vec<f32>>,
}

impl Uploader for HostUploader {
    fn values(&mut self, values: &[f32]) -> u64 {
        values.as_ptr() as u64
    }

    fn grid(
        &mut self,
        values: &[f32],
        res: [u32; 3],
        channels: u32,
        placement: GridPlacement,
        _texel: TexelFormat,
    ) -> PlacedGrid {
        // A texture stays dense samples here: the CPU filters them as a texture unit would.
        if self.layout == GridLayout::Dense || placement != GridPlacement::AnyLayout {
            return PlacedGrid {
                address: self.values(values),
                len: values.len() as u64,
                layout: GridLayout::Dense,
                texture: 0,
            };
        }
        let bricked = volpt_gpu_mem::layout::bricked(values, res, channels).expect("memory");
        let placed = PlacedGrid {
            address: bricked.as_ptr() as u64,
            len: bricked.len() as u64,
            layout: GridLayout::Bricked,
            texture: 0,
        };
        // The vector's heap buffer does not move when the vector does.
        self.buffers.push(bricked);
        placed
    }

    /// As the GPU's uploader: the flat copy, the only sparse layout the kernels read.
    fn sparse(&mut self, data: &[f32], res: [u32; 3], _channels: u32) -> PlacedGrid {
        let flat = volpt_core::sparse::flatten(data, res).expect("a small test grid");
        let placed = PlacedGrid {
            address: flat.as_ptr() as u64,
            len: flat.len() as u64,
            layout: GridLayout::SparseFlat,
            texture: 0,
        };
        self.buffers.push(flat);
        placed
    }
}

/// Renders the scene, the scene rebuilt from its launch parameters with grids in `layout`, and
/// the scene a mesh-capable kernel rebuilds from them (`SceneAbi::Kernel`: its boundary a
/// `DeviceBoundary`).
struct RoundTrip {
    layout: GridLayout,
}

impl SceneVisitor for RoundTrip {
    type Output = (Image, Image, Image);

    fn visit<S: RenderScene>(self, scene: &S) -> Self::Output {
        let mut uploader = HostUploader {
            layout: self.layout,
            buffers: Vec::new(),
        };
        let params = scene.to_params(&mut uploader);
        // SAFETY: every address is a slice of the description or of `uploader`, alive for this
        // whole visit.
        let rebuilt = unsafe { S::from_params(&params) };
        // SAFETY: as above.
        let kernel = unsafe { <S::Kernel as SceneAbi>::from_params(&params) };
        let options = RenderOptions {
            spp: 4,
            seed: 11,
            threads: None,
        };
        let original = render(scene, &options, &|_, _| {}).expect("render");
        let decoded = render(&rebuilt, &options, &|_, _| {}).expect("render");
        let kernels = render(&kernel, &options, &|_, _| {}).expect("render");
        (original.0, decoded.0, kernels.0)
    }
}

#[test]
fn every_variant_survives_the_device_abi_bit_for_bit() {
    round_trips(GridLayout::Dense);
}

/// Grids rewritten in 8^3 bricks (padding included: the test grids are 4x3x2) are read by the
/// device code exactly as the dense grids they came from.
#[test]
fn every_variant_with_bricked_grids_renders_bit_for_bit() {
    round_trips(GridLayout::Bricked);
}

/// Grids in the sparse layout (stored bricks and a brick table, `volpt_core::GridLayout::Sparse`)
/// travel to the device as their flat copy (`GridLayout::SparseFlat`, what the GPU's uploader
/// places) and are read by the device code exactly as the dense grids they came from; they
/// select the any-layout medium, as bricked storage does.
#[test]
fn every_variant_with_sparse_grids_renders_bit_for_bit() {
    let mut descs = descriptions();
    descs.retain(|d| {
        !matches!(
            d.medium.lookup,
            GridLookup::Texture | GridLookup::TextureHalf
        )
    });
    for desc in &mut descs {
        if let DensityDesc::Grid(g) = &mut desc.medium.density {
            *g = g.sparsified();
        }
        if let AlbedoDesc::Grid(g) = &mut desc.medium.albedo {
            *g = g.sparsified();
        }
    }
    let mut expected: BTreeSet<String> = volpt_core::variant::NAMES
        .iter()
        .map(|names| names.join("/"))
        .collect();
    expected.retain(|v| reads_any_layout_or_no_grid(v));
    check_round_trips(descs, expected, GridLayout::Dense);
}

fn round_trips(layout: GridLayout) {
    let mut descs = descriptions();
    // Dense: every variant of the registry. Bricked storage selects the any-layout grid medium for
    // every grid but textures, so that the uploader may brick it: its variants and the homogeneous
    // ones (the texture medium's are left out).
    let mut expected: BTreeSet<String> = volpt_core::variant::NAMES
        .iter()
        .map(|names| names.join("/"))
        .collect();
    if layout == GridLayout::Bricked {
        descs.retain(|d| d.medium.lookup != GridLookup::TextureHalf);
        for desc in &mut descs {
            desc.medium.storage = GridStorage::Bricked;
        }
        expected.retain(|v| reads_any_layout_or_no_grid(v));
    }
    check_round_trips(descs, expected, layout);
}

/// Whether the variant `v` (`medium/boundary/phase/environment`) has a medium that reads no grid
/// or reads its grids in any layout (its composed name ends with [`AnyLayout`]'s): the media that
/// bricked and sparse grids select.
fn reads_any_layout_or_no_grid(v: &str) -> bool {
    let medium = v.split('/').next().unwrap_or_default();
    // The examples' chromatic medium has a constant albedo: it reads no grid.
    medium == HomogeneousMedium::NAME
        || medium == volpt_core::ChromaticMedium::NAME
        || medium.ends_with(&format!("__{}", AnyLayout::NAME))
}

/// Each description renders the same through the device ABI (grids placed in `layout` where
/// the medium reads any layout), and the descriptions cover exactly the `expected` variants.
fn check_round_trips(descs: Vec<SceneDescription>, expected: BTreeSet<String>, layout: GridLayout) {
    let variants: BTreeSet<String> = descs.iter().map(|d| Variant::of(d).to_string()).collect();
    assert_eq!(
        variants, expected,
        "the descriptions cover exactly the registry's variants"
    );
    for desc in &descs {
        let trip = RoundTrip { layout };
        let (original, decoded, kernels) =
            with_scene(desc, volpt_render::path_settings(desc), trip);
        assert!(
            original.pixels.iter().flatten().any(|&v| v > 0.0),
            "{}: a black image proves nothing",
            Variant::of(desc)
        );
        let differing = (original.pixels.iter())
            .zip(&decoded.pixels)
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(differing, 0, "{}: pixels that differ", Variant::of(desc));
        assert!(
            kernels.pixels == original.pixels,
            "{}: the kernels' scene type renders another image",
            Variant::of(desc)
        );
    }
}

/// The worked extension of `docs/extending.md`: `GridMedium<ConstantAlbedo, AnyLayout>`, which the
/// registry does not list, needs nothing but its registry line. Its name is its own (composed from
/// its parameters'), the factory's generic rule builds it from a description, and it crosses the
/// device ABI bit for bit, rendering what the registry's any-layout medium renders with the
/// constant albedo as a one-voxel grid.
#[test]
fn a_new_instantiation_needs_only_its_registry_line() {
    use volpt_core::{ConstantAlbedo, GridMedium, Isotropic, NullBoundary, VolumeScene};
    use volpt_render::factory::{camera, medium_input, Effects, FactoryCache};
    use volpt_scene::FromDescription;

    type New<'a> = GridMedium<'a, ConstantAlbedo, AnyLayout>;
    assert_eq!(New::NAME, "grid_density__constant_albedo__any_layout");
    assert!(volpt_core::variant::NAMES.iter().all(|v| v[0] != New::NAME));

    let desc = descriptions()
        .into_iter()
        .find(|d| {
            d.medium.lookup == GridLookup::Nearest
                && matches!(d.medium.albedo, AlbedoDesc::Constant(_))
                && d.boundary.bsdf == BsdfDesc::Null
                && d.medium.phase == PhaseDesc::Isotropic
                && matches!(d.environment, EnvironmentDesc::Constant(_))
        })
        .expect("a constant albedo read in any layout");
    let input = medium_input(
        &desc,
        Effects::Specialised,
        &FactoryCache::new(),
        &mut |_| (),
    );
    let medium =
        <New as FromDescription>::specialised(&input, &mut |_| ()).expect("the generic rule");
    let EnvironmentDesc::Constant(rgb) = desc.environment else {
        unreachable!()
    };
    let bounds = &desc.boundary.bounds;
    let scene = VolumeScene {
        camera: camera(&desc.camera, &desc.film),
        bounds: volpt_core::Aabb::new(bounds.min.into(), bounds.max.into()),
        settings: volpt_render::path_settings(&desc),
        medium,
        boundary: NullBoundary,
        phase: Isotropic,
        environment: volpt_core::ConstantEnvironment(rgb.into()),
        lights: volpt_core::Lights::NONE,
    };
    let (new, decoded, kernel) = RoundTrip {
        layout: GridLayout::Bricked,
    }
    .visit(&scene);
    assert!(new.pixels.iter().flatten().any(|&v| v > 0.0));
    assert!(
        new.pixels == decoded.pixels && new.pixels == kernel.pixels,
        "the device ABI changed the image"
    );
    let (registry, _, _) = with_scene(
        &desc,
        volpt_render::path_settings(&desc),
        RoundTrip {
            layout: GridLayout::Dense,
        },
    );
    assert!(
        new.pixels == registry.pixels,
        "a one-voxel albedo is the constant"
    );
}
