//! Mesh boundaries from scene files: a TOML `[boundary] mesh` placed by scale, rotation and
//! translation, with the grid over the mesh's bounding box; Mitsuba's `cube` under any
//! `to_world`, `sphere`, `obj` and `ply`; and one clear error for each mistake these paths open.

mod common;

use std::path::{Path, PathBuf};

use common::{assert_close3, density_grid, message_of, scene_file, unit_bounds, write_grid};
use volpt_scene::{builder_for, load_mitsuba, Config, DensityDesc, SceneAssembler, SceneError};

/// The unit cube's 6 faces as quads, counter-clockwise seen from outside (corner `i` is at x = 1
/// if bit 0 is set, y = 1 bit 1, z = 1 bit 2).
const QUADS: [[u32; 4]; 6] = [
    [0, 4, 6, 2],
    [1, 3, 7, 5],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 2, 3, 1],
    [4, 5, 7, 6],
];

/// The unit cube [0, 1]^3 as an OBJ; `reversed` turns every face inwards.
fn cube_obj(reversed: bool) -> String {
    let mut text = String::new();
    for i in 0..8 {
        text += &format!("v {} {} {}\n", i & 1, (i >> 1) & 1, (i >> 2) & 1);
    }
    for q in QUADS {
        let q = if reversed {
            [q[3], q[2], q[1], q[0]]
        } else {
            q
        };
        text += &format!("f {} {} {} {}\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
    }
    text
}

/// The octahedron with vertices at +-1 on each axis, as an ASCII PLY.
fn octahedron_ply() -> String {
    let vertices = [
        [1, 0, 0],
        [-1, 0, 0],
        [0, 1, 0],
        [0, -1, 0],
        [0, 0, 1],
        [0, 0, -1],
    ];
    let mut faces = Vec::new();
    for octant in 0..8 {
        let (x, y, z) = (octant & 1, 2 + ((octant >> 1) & 1), 4 + ((octant >> 2) & 1));
        // Each negative axis mirrors the octant's triangle: an odd count reverses it.
        let negatives = (octant & 1) + ((octant >> 1) & 1) + ((octant >> 2) & 1);
        faces.push(if negatives % 2 == 0 {
            [x, y, z]
        } else {
            [x, z, y]
        });
    }
    let mut text = String::from(
        "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n\
         property float z\nelement face 8\nproperty list uchar int vertex_indices\nend_header\n",
    );
    for v in vertices {
        text += &format!("{} {} {}\n", v[0], v[1], v[2]);
    }
    for f in faces {
        text += &format!("3 {} {} {}\n", f[0], f[1], f[2]);
    }
    text
}

/// A TOML scene over a 2x2x2 `.vol` grid whose file box is the unit cube, with a unit-cube mesh
/// `cube.obj` beside it; `boundary` is the `[boundary]` table's body.
fn toml_scene(boundary: &str, volume_extra: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("temp dir");
    write_grid(dir.path(), "g.vol", &density_grid([2, 2, 2], unit_bounds()));
    std::fs::write(dir.path().join("cube.obj"), cube_obj(false)).unwrap();
    std::fs::write(dir.path().join("inside_out.obj"), cube_obj(true)).unwrap();
    let text = format!(
        "[volume]\nfile = \"g.vol\"\n{volume_extra}\n[boundary]\nbsdf = \"null\"\n{boundary}\n"
    );
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    (dir, path)
}

fn load(path: &Path) -> Result<volpt_scene::SceneDescription, SceneError> {
    SceneAssembler::new(Config::default()).assemble(builder_for(path)?.as_ref())
}

fn grid_bounds(desc: &volpt_scene::SceneDescription) -> volpt_scene::Bounds {
    let DensityDesc::Grid(grid) = &desc.medium.density else {
        panic!("a grid density")
    };
    grid.bounds
}

#[test]
fn a_toml_mesh_is_scaled_rotated_then_translated_and_the_grid_lies_over_its_box() {
    let (_dir, path) = toml_scene(
        "mesh = \"cube.obj\"\nscale = [2.0, 1.0, 1.0]\n\
         rotate = { axis = [0, 0, 1], angle = 90 }\ntranslate = [10.0, 0.0, 0.0]",
        "",
    );
    let desc = load(&path).expect("scene loads");
    let mesh = desc.boundary.mesh.as_ref().expect("a mesh boundary");
    assert_eq!(mesh.triangle_count(), 12);
    assert!(mesh.source.ends_with("cube.obj"), "{}", mesh.source);
    // x in [0, 2] turns (counter-clockwise about z) into y in [0, 2]; y in [0, 1] into x in
    // [-1, 0]; then x moves by 10.
    assert_close3(desc.boundary.bounds.min, [9.0, 0.0, 0.0]);
    assert_close3(desc.boundary.bounds.max, [10.0, 2.0, 1.0]);
    assert_eq!(grid_bounds(&desc), desc.boundary.bounds);
}

#[test]
fn volume_bounds_place_the_grid_apart_from_the_mesh() {
    let (_dir, path) = toml_scene(
        "mesh = \"cube.obj\"\nscale = 3.0",
        "bounds = [[0.5, 0.5, 0.5], [1.5, 1.5, 1.5]]",
    );
    let desc = load(&path).expect("scene loads");
    assert_close3(desc.boundary.bounds.max, [3.0; 3]);
    assert_eq!(grid_bounds(&desc).min, [0.5; 3]);
    assert_eq!(grid_bounds(&desc).max, [1.5; 3]);
}

#[test]
fn a_mirrored_mesh_is_turned_to_face_outwards_and_an_inside_out_file_is_refused() {
    // A mirror would turn every triangle inwards; the loader reverses them, so it loads.
    let (_dir, path) = toml_scene("mesh = \"cube.obj\"\nscale = [-1.0, 1.0, 1.0]", "");
    let desc = load(&path).expect("a mirrored mesh loads");
    assert_close3(desc.boundary.bounds.min, [-1.0, 0.0, 0.0]);

    let (_dir, path) = toml_scene("mesh = \"inside_out.obj\"", "");
    let err = load(&path).unwrap_err();
    message_of(&err, &["inside_out.obj", "faces inwards"]);
}

#[test]
fn toml_mesh_mistakes_are_named() {
    let cases: [(&str, &[&str]); 7] = [
        (
            "mesh = \"cube.obj\"\nbounds = [[0, 0, 0], [1, 1, 1]]",
            &["boundary.bounds", "mesh's bounding box"],
        ),
        ("scale = 2.0", &["boundary.scale", "a boundary.mesh"]),
        (
            "mesh = \"cube.obj\"\nscale = 0.0",
            &["boundary.scale", "non-zero"],
        ),
        (
            "mesh = \"cube.obj\"\nrotate = { axis = [0, 0, 0], angle = 5 }",
            &["boundary.rotate", "not zero"],
        ),
        (
            "mesh = \"cube.obj\"\nrotate = { axis = [0, 0, 1] }",
            &["angle"],
        ),
        ("mesh = \"missing.stl\"", &["missing.stl"]),
        ("mesh = \"g.vol\"", &["g.vol", ".obj, .ply or .stl"]),
    ];
    for (boundary, parts) in cases {
        let (_dir, path) = toml_scene(boundary, "");
        let err = load(&path).expect_err(boundary);
        message_of(&err, parts);
    }
}

/// A Mitsuba 3 scene whose one shape is `shape` (its opening tag and parameters).
fn mitsuba(shape: &str, kind: &str) -> String {
    format!(
        "<scene version=\"3.0.0\">\n\
         \x20   <sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/></sensor>\n\
         \x20   <shape type=\"{kind}\">\n{shape}\n        <bsdf type=\"null\"/>\n\
         \x20       <medium type=\"homogeneous\" name=\"interior\"/>\n    </shape>\n\
         </scene>\n"
    )
}

#[test]
fn a_cube_under_any_rotation_is_its_12_triangles_and_an_aligned_one_the_box() {
    let (_dir, path) = scene_file(&mitsuba(
        "<transform name=\"to_world\"><rotate z=\"1\" angle=\"45\"/></transform>",
        "cube",
    ));
    let desc = load_mitsuba(&path).expect("scene loads");
    let mesh = desc
        .boundary
        .mesh
        .as_ref()
        .expect("a rotated cube is a mesh");
    assert_eq!(mesh.triangle_count(), 12);
    let r = 2f32.sqrt();
    assert_close3(desc.boundary.bounds.min, [-r, -r, -1.0]);
    assert_close3(desc.boundary.bounds.max, [r, r, 1.0]);

    let (_dir, path) = scene_file(&mitsuba(
        "<transform name=\"to_world\"><scale x=\"2\"/><rotate z=\"1\" angle=\"90\"/></transform>",
        "cube",
    ));
    let desc = load_mitsuba(&path).expect("scene loads");
    assert!(
        desc.boundary.mesh.is_none(),
        "an axis-aligned cube is the box"
    );
}

#[test]
fn a_sphere_is_a_mesh_inscribed_in_it() {
    let (_dir, path) = scene_file(&mitsuba(
        "<point name=\"center\" x=\"1\" y=\"2\" z=\"3\"/><float name=\"radius\" value=\"2\"/>\n\
         <transform name=\"to_world\"><translate x=\"10\"/></transform>",
        "sphere",
    ));
    let desc = load_mitsuba(&path).expect("scene loads");
    let mesh = desc.boundary.mesh.as_ref().expect("a sphere is a mesh");
    assert_eq!(mesh.triangle_count(), 2 * 128 * 63);
    let center = [11.0f64, 2.0, 3.0];
    for t in &mesh.buffers.triangles {
        for v in t.v {
            let d = (0..3)
                .map(|k| (f64::from(v[k]) - center[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(
                (d - 2.0).abs() < 1e-5,
                "vertex {v:?} at {d} from the centre"
            );
        }
    }
    assert_close3(desc.boundary.bounds.min, [9.0, 0.0, 1.0]);
    assert_close3(desc.boundary.bounds.max, [13.0, 4.0, 5.0]);
}

#[test]
fn obj_and_ply_meshes_are_placed_by_to_world_and_a_box_obj_stays_the_box() {
    let (dir, path) = scene_file(&mitsuba(
        "<string name=\"filename\" value=\"octahedron.ply\"/>\n\
         <transform name=\"to_world\"><scale value=\"2\"/><translate z=\"5\"/></transform>",
        "ply",
    ));
    std::fs::write(dir.path().join("octahedron.ply"), octahedron_ply()).unwrap();
    let desc = load_mitsuba(&path).expect("scene loads");
    assert_eq!(desc.boundary.mesh.as_ref().unwrap().triangle_count(), 8);
    assert_close3(desc.boundary.bounds.min, [-2.0, -2.0, 3.0]);
    assert_close3(desc.boundary.bounds.max, [2.0, 2.0, 7.0]);

    let (dir, path) = scene_file(&mitsuba(
        "<string name=\"filename\" value=\"cube.obj\"/>",
        "obj",
    ));
    std::fs::write(dir.path().join("cube.obj"), cube_obj(false)).unwrap();
    let desc = load_mitsuba(&path).expect("scene loads");
    assert!(
        desc.boundary.mesh.is_none(),
        "a box's 8 corners are the box"
    );
    assert_eq!(desc.boundary.bounds.max, [1.0; 3]);
}

#[test]
fn mitsuba_mesh_mistakes_are_named() {
    let (_dir, path) = scene_file(&mitsuba(
        "<boolean name=\"flip_normals\" value=\"true\"/>",
        "sphere",
    ));
    message_of(
        &load_mitsuba(&path).unwrap_err(),
        &["flip_normals", "expected false"],
    );

    let (_dir, path) = scene_file(&mitsuba("<float name=\"radius\" value=\"-1\"/>", "sphere"));
    message_of(&load_mitsuba(&path).unwrap_err(), &["positive radius"]);

    // A scale of zero flattens the cube: every triangle degenerate.
    let (_dir, path) = scene_file(&mitsuba(
        "<transform name=\"to_world\"><rotate z=\"1\" angle=\"30\"/><scale z=\"0\"/></transform>",
        "cube",
    ));
    message_of(
        &load_mitsuba(&path).unwrap_err(),
        &["<shape type=\"cube\">", "degenerate"],
    );

    let (dir, path) = scene_file(&mitsuba(
        "<string name=\"filename\" value=\"inside_out.obj\"/>\n\
         <transform name=\"to_world\"><rotate z=\"1\" angle=\"30\"/></transform>",
        "obj",
    ));
    std::fs::write(dir.path().join("inside_out.obj"), cube_obj(true)).unwrap();
    message_of(
        &load_mitsuba(&path).unwrap_err(),
        &["inside_out.obj", "faces inwards"],
    );
}

/// Each triangle as the bits of its three corners, rotated to start at its smallest corner (the
/// same triangle, whatever corner a file lists first), in order.
fn triangle_set(mesh: &volpt_scene::MeshDesc) -> Vec<[[u32; 3]; 3]> {
    let mut set: Vec<[[u32; 3]; 3]> = mesh
        .buffers
        .triangles
        .iter()
        .map(|t| {
            let v = t.v.map(|p| p.map(f32::to_bits));
            let first = (0..3).min_by_key(|&i| v[i]).unwrap();
            [v[first], v[(first + 1) % 3], v[(first + 2) % 3]]
        })
        .collect();
    set.sort_unstable();
    set
}

#[test]
fn an_exported_mesh_scene_reads_back_as_the_same_mesh() {
    let (dir, path) = scene_file(&mitsuba(
        "<float name=\"radius\" value=\"0.5\"/>\n\
         <transform name=\"to_world\"><scale z=\"2\"/><rotate x=\"1\" angle=\"30\"/></transform>",
        "sphere",
    ));
    let desc = load_mitsuba(&path).expect("scene loads");
    let out = dir.path().join("export");
    let written = volpt_scene::mitsuba::write_mitsuba3(&desc, &out, "ellipsoid").expect("export");
    assert!(written
        .iter()
        .any(|p| p.ends_with("ellipsoid-boundary.ply")));
    let xml = std::fs::read_to_string(&written[0]).unwrap();
    assert!(xml.contains("<shape type=\"ply\">") && xml.contains("face_normals"));
    let back = load_mitsuba(&written[0]).expect("the export loads");
    let (a, b) = (
        desc.boundary.mesh.as_ref().unwrap(),
        back.boundary.mesh.as_ref().unwrap(),
    );
    assert_eq!(triangle_set(a), triangle_set(b));
    assert_eq!(desc.boundary.bounds, back.boundary.bounds);
}

/// The BVH built on several threads is the serial build's, node for node and triangle for
/// triangle: the subtrees are concatenated in the serial order (a mesh large enough that its
/// top levels fork), whichever thread finishes first.
#[test]
fn the_threaded_bvh_build_is_the_serial_one() {
    use volpt_core::mesh::build::{build, build_with};
    use volpt_core::mesh::primitives::{sphere, torus};
    use volpt_scene::mesh::Threads;
    for (what, (vertices, triangles)) in [
        ("sphere", sphere([0.1, 0.0, 0.0], 1.0, 140, 280)),
        ("torus", torus([0.0; 3], 1.0, 0.3, 280, 140)),
    ] {
        assert!(triangles.len() > 2 * (1 << 15), "{what}: too small to fork");
        let serial = build(&vertices, &triangles).expect("closed");
        for threads in [2, 3, 8] {
            let threaded =
                build_with(&vertices, &triangles, &Threads::new(threads)).expect("closed");
            assert!(
                threaded == serial,
                "{what}: {threads} threads build another BVH"
            );
        }
    }
}

/// Mitsuba 3 shades an `obj` or `ply` with interpolated vertex normals unless `face_normals` is
/// true: the file's, or where it has none, smooth ones it computes. volpt does the same for a
/// dielectric surface (an index-matched one has nothing to shade): the octahedron's smooth
/// normals are its vertices' directions (by symmetry), and a file's own normals are placed by the
/// inverse transpose of `to_world`.
#[test]
fn a_dielectric_mesh_is_shaded_with_vertex_normals_unless_face_normals_is_true() {
    let dielectric = |shape: &str, kind: &str| {
        mitsuba(shape, kind).replace("<bsdf type=\"null\"/>", "<bsdf type=\"dielectric\"/>")
    };
    let file = "<string name=\"filename\" value=\"octahedron.ply\"/>";
    let face = "<boolean name=\"face_normals\" value=\"true\"/>";
    for (xml, shaded) in [
        (dielectric(file, "ply"), true),
        (dielectric(&format!("{file}{face}"), "ply"), false),
        (mitsuba(file, "ply"), false),
    ] {
        let (dir, path) = scene_file(&xml);
        std::fs::write(dir.path().join("octahedron.ply"), octahedron_ply()).unwrap();
        let desc = load_mitsuba(&path).expect("scene loads");
        let mesh = desc.boundary.mesh.as_ref().expect("a mesh");
        let buffers = &mesh.buffers;
        assert_eq!(!buffers.normals.is_empty(), shaded, "{xml}");
        // Exported for Mitsuba 3, with its normals where it has them, it reads back the same.
        let written =
            volpt_scene::mitsuba::write_mitsuba3(&desc, &dir.path().join("export"), "o").unwrap();
        let again = load_mitsuba(&written[0]).expect("the export loads");
        let again = &again.boundary.mesh.as_ref().expect("a mesh").buffers;
        let corners = |b: &volpt_core::mesh::build::MeshBuffers| {
            let mut c: Vec<[u32; 6]> = (0..b.triangles.len())
                .flat_map(|i| {
                    let n = b.normals.get(i).copied().unwrap_or([[0.0; 3]; 3]);
                    (0..3).map(move |k| {
                        let (v, n) = (b.triangles[i].v[k], n[k]);
                        [v[0], v[1], v[2], n[0], n[1], n[2]].map(f32::to_bits)
                    })
                })
                .collect();
            c.sort_unstable();
            c
        };
        assert_eq!(corners(buffers), corners(again), "{xml}");
        for (tri, normals) in buffers.triangles.iter().zip(&buffers.normals) {
            for (v, n) in tri.v.iter().zip(normals) {
                for axis in 0..3 {
                    assert!((v[axis] - n[axis]).abs() < 1e-6, "{v:?} has normal {n:?}");
                }
            }
        }
    }

    // A tetrahedron's OBJ with a normal per corner, squashed along z: a normal (0, 0, 1) stays
    // (0, 0, 1), a normal (1, 0, 1) / sqrt 2 becomes (1, 0, 2) / sqrt 5 (inverse transpose).
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
               vn 0 0 1\nvn 0.70710678 0 0.70710678\n\
               f 1//1 3//1 2//1\nf 1//2 2//2 4//2\nf 1//1 4//1 3//1\nf 2//2 3//2 4//2\n";
    let (dir, path) = scene_file(&dielectric(
        "<string name=\"filename\" value=\"tet.obj\"/>\
         <transform name=\"to_world\"><scale z=\"0.5\"/></transform>",
        "obj",
    ));
    std::fs::write(dir.path().join("tet.obj"), obj).unwrap();
    let desc = load_mitsuba(&path).expect("scene loads");
    let buffers = &desc.boundary.mesh.as_ref().expect("a mesh").buffers;
    let s5 = 1.0 / 5.0f32.sqrt();
    let mut seen = [0; 2];
    for n in buffers.normals.iter().flatten() {
        if (n[0] - s5).abs() < 1e-6 && n[1] == 0.0 && (n[2] - 2.0 * s5).abs() < 1e-6 {
            seen[1] += 1;
        } else {
            assert_eq!(*n, [0.0, 0.0, 1.0]);
            seen[0] += 1;
        }
    }
    assert_eq!(seen, [6, 6]);
}

/// A PLY's vertex normal of no length is refused, naming the triangle and its corner.
#[test]
fn a_vertex_normal_of_no_length_is_refused_naming_its_triangle() {
    let ply = octahedron_ply().replace(
        "property float z\n",
        "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n",
    );
    // Each vertex line gets its position as its normal; the first vertex gets none.
    let mut lines: Vec<String> = ply.lines().map(String::from).collect();
    let body = lines.iter().position(|l| l == "end_header").unwrap() + 1;
    for (k, line) in lines[body..body + 6].iter_mut().enumerate() {
        let normal = if k == 0 {
            "0 0 0".to_string()
        } else {
            line.clone()
        };
        *line = format!("{line} {normal}");
    }
    let (dir, path) = scene_file(
        &mitsuba(
            "<string name=\"filename\" value=\"octahedron.ply\"/>",
            "ply",
        )
        .replace("<bsdf type=\"null\"/>", "<bsdf type=\"dielectric\"/>"),
    );
    std::fs::write(dir.path().join("octahedron.ply"), lines.join("\n") + "\n").unwrap();
    message_of(
        &load_mitsuba(&path).unwrap_err(),
        &[
            "octahedron.ply",
            "vertex normal",
            "triangle",
            "[0.0, 0.0, 0.0]",
        ],
    );
}
