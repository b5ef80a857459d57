//! Mesh boundaries from scene files through the factory, on the CPU: a box written as a mesh of
//! 24 triangles (each face split at its centre, so that it is not read as the box's 8 corners)
//! renders the box scene's image bit for bit, on the CPU's boundary and on the one a
//! mesh-capable kernel rebuilds from the launch parameters (`DeviceBoundary`, run on the CPU).

use std::path::Path;

use volpt_core::SceneAbi;
use volpt_render::{
    path_settings, render, with_scene, Image, RenderOptions, RenderScene, SceneVisitor,
};
use volpt_scene::{load_mitsuba, SceneDescription};

/// The box [-0.5, 0.5]^3 with each face split into 4 triangles at its centre, counter-clockwise
/// seen from outside, as an OBJ.
fn split_box_obj() -> String {
    let mut text = String::new();
    for i in 0..8 {
        let c = |bit: i32| if i & (1 << bit) != 0 { 0.5 } else { -0.5 };
        text += &format!("v {} {} {}\n", c(0), c(1), c(2));
    }
    let quads: [[u32; 4]; 6] = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    for (f, q) in quads.iter().enumerate() {
        // The face's centre: the mean of its corners, exact in binary.
        let corner = |k: u32| [0, 1, 2].map(|a| if k & (1 << a) != 0 { 0.5 } else { -0.5 });
        let centre: [f64; 3] =
            [0, 1, 2].map(|a| q.iter().map(|&k| corner(k)[a]).sum::<f64>() / 4.0);
        text += &format!("v {} {} {}\n", centre[0], centre[1], centre[2]);
        let m = 9 + f as u32;
        for e in 0..4 {
            text += &format!("f {} {} {}\n", q[e] + 1, q[(e + 1) % 4] + 1, m);
        }
    }
    text
}

fn scene(shape: &str, bsdf: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <integrator type="volpath"><integer name="max_depth" value="-1"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="1.0"/>
        <transform name="to_world"><lookat origin="20, 30, 100" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
        <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
    {shape}
        {bsdf}
        <medium type="homogeneous" name="interior">
            <float name="sigma_t" value="8"/>
            <rgb name="albedo" value="0.9"/>
        </medium>
    </shape>
</scene>
"#
    )
}

fn load(dir: &Path, name: &str, text: &str) -> SceneDescription {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    load_mitsuba(&path).expect("scene loads")
}

/// The scene's CPU image, the image of the scene rebuilt from its launch parameters as a
/// `DeviceBoundary` scene (`SceneAbi::Kernel`), rendered on the CPU with "device addresses" that
/// are the host's own slices, and whether the (box) kernels take the scene.
struct Cpu;

impl SceneVisitor for Cpu {
    type Output = (Image, Image, bool);
    fn visit<S: RenderScene>(self, scene: &S) -> Self::Output {
        let options = RenderOptions {
            spp: 4,
            seed: 7,
            threads: None,
        };
        let (image, _) = render(scene, &options, &|_, _| {}).expect("render");
        let params = scene.to_params(&mut |values: &[f32]| values.as_ptr() as u64);
        // SAFETY: every address is a slice of the description, alive for this whole visit.
        let kernel = unsafe { <S::Kernel as SceneAbi>::from_params(&params) };
        let (kernel_image, _) = render(&kernel, &options, &|_, _| {}).expect("render");
        (image, kernel_image, scene.on_device())
    }
}

#[test]
fn a_box_written_as_a_mesh_renders_the_box_image_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("box.obj"), split_box_obj()).unwrap();
    let cube = r#"<shape type="cube"><transform name="to_world"><scale value="0.5"/></transform>"#;
    // face_normals: the box's faces, not smooth normals interpolated over its corners.
    let obj = r#"<shape type="obj"><string name="filename" value="box.obj"/><boolean name="face_normals" value="true"/>"#;
    for bsdf in [
        r#"<bsdf type="null"/>"#,
        r#"<bsdf type="dielectric"><float name="int_ior" value="1.33"/></bsdf>"#,
        r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/><float name="alpha" value="0.2"/></bsdf>"#,
    ] {
        let boxed = load(dir.path(), "box.xml", &scene(cube, bsdf));
        let meshed = load(dir.path(), "mesh.xml", &scene(obj, bsdf));
        assert!(boxed.boundary.mesh.is_none());
        assert_eq!(meshed.boundary.mesh.as_ref().unwrap().triangle_count(), 24);
        assert_eq!(boxed.boundary.bounds, meshed.boundary.bounds);
        let (box_image, box_kernel, box_on_device) = with_scene(&boxed, path_settings(&boxed), Cpu);
        let (mesh_image, mesh_kernel, mesh_on_device) =
            with_scene(&meshed, path_settings(&meshed), Cpu);
        assert!(box_image.pixels.iter().any(|p| *p != box_image.pixels[0]));
        assert!(
            box_image.pixels == mesh_image.pixels,
            "{bsdf}: the mesh's image differs from the box's"
        );
        assert!(
            box_kernel.pixels == box_image.pixels,
            "{bsdf}: the kernels' box scene differs from the host's"
        );
        assert!(
            mesh_kernel.pixels == box_image.pixels,
            "{bsdf}: the kernels' mesh scene differs from the box's"
        );
        assert!(box_on_device, "the kernels render a box");
        assert!(!mesh_on_device, "the box kernels do not render a mesh");
    }
}

/// A sphere mesh's BVH crosses the launch parameters: the scene rebuilt from them as a
/// `DeviceBoundary` scene renders the CPU's image bit for bit (a lost mesh would render its
/// bounding box), behind each boundary kind.
#[test]
fn a_sphere_mesh_crosses_the_launch_parameters_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = r#"<shape type="sphere"><float name="radius" value="0.5"/>"#;
    let cube = r#"<shape type="cube"><transform name="to_world"><scale value="0.5"/></transform>"#;
    for bsdf in [
        r#"<bsdf type="null"/>"#,
        r#"<bsdf type="dielectric"><float name="int_ior" value="1.33"/></bsdf>"#,
        r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/><float name="alpha" value="0.2"/></bsdf>"#,
    ] {
        let meshed = load(dir.path(), "sphere.xml", &scene(sphere, bsdf));
        let boxed = load(dir.path(), "box.xml", &scene(cube, bsdf));
        let (image, kernel, on_device) = with_scene(&meshed, path_settings(&meshed), Cpu);
        let (box_image, _, _) = with_scene(&boxed, path_settings(&boxed), Cpu);
        assert!(!on_device);
        assert!(
            image.pixels != box_image.pixels,
            "{bsdf}: the sphere renders its box"
        );
        assert!(
            kernel.pixels == image.pixels,
            "{bsdf}: the sphere rebuilt from its parameters renders another image"
        );
    }
}
