//! Scenes no kernel traces are refused before anything is uploaded, with an error that names the
//! CPU: a mesh whose dielectric surface scatters about interpolated vertex normals (the kernels
//! carry the triangles' own normals only). No GPU needed.

use volpt_core::mesh::build::build;
use volpt_core::mesh::primitives::sphere;
use volpt_core::{
    BoundaryShape, ConstantEnvironment, HenyeyGreenstein, HomogeneousMedium, PathSettings,
    PerspectiveCamera, SmoothDielectric, Spectrum, Vec2, Vec3, VolumeScene,
};
use volpt_cuda::entry::scene_entry;
use volpt_cuda::CudaError;
use volpt_device::Strategy;

#[test]
fn a_mesh_with_vertex_normals_is_refused_by_the_gpu_and_the_same_mesh_without_them_is_not() {
    let (vertices, triangles) = sphere([0.0; 3], 1.0, 6, 12);
    let flat = build(&vertices, &triangles).unwrap();
    let radial: Vec<[[f32; 3]; 3]> = triangles
        .iter()
        .map(|t| t.map(|i| Vec3::from(vertices[i as usize]).normalize().to_array()))
        .collect();
    let shaded = flat.clone().with_vertex_normals(&radial).unwrap();
    fn scene(
        buffers: &volpt_core::mesh::build::MeshBuffers,
    ) -> VolumeScene<
        HomogeneousMedium,
        SmoothDielectric,
        HenyeyGreenstein,
        ConstantEnvironment,
        BoundaryShape<'_>,
    > {
        let mesh = buffers.mesh();
        VolumeScene {
            camera: PerspectiveCamera {
                origin: Vec3::new(0.0, 0.0, -4.0),
                axis_x: Vec3::X,
                axis_y: Vec3::Y,
                axis_z: Vec3::Z,
                tan_half_fov: Vec2::splat(0.4),
                width: 8,
                height: 8,
                orthographic: false,
            },
            bounds: BoundaryShape::Mesh(mesh),
            medium: HomogeneousMedium {
                sigma_t: 1.0,
                albedo: Spectrum::splat(0.9),
            },
            boundary: SmoothDielectric { eta: 1.5 },
            phase: HenyeyGreenstein { g: 0.0 },
            environment: ConstantEnvironment(Spectrum::ONE),
            lights: volpt_core::Lights::NONE,
            settings: PathSettings::default(),
        }
    }
    let refused = scene_entry(&scene(&shaded), Strategy::RegenerationSk).unwrap_err();
    assert!(matches!(refused, CudaError::ShadingNormals), "{refused}");
    let message = refused.to_string();
    for needle in ["vertex normals", "--backend cpu", "face_normals"] {
        assert!(message.contains(needle), "{message}");
    }
    let entry = scene_entry(&scene(&flat), Strategy::RegenerationSk).expect("mesh kernels");
    assert!(entry.starts_with("mesh__"), "{entry}");
}
