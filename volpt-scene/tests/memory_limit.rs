//! The memory limit (issue 12): lowered for this test binary alone (it is one setting per process),
//! data whose declared size exceeds it is refused before it is allocated, with the file, what it
//! is and its size in the message; data within it loads.

mod common;

use std::io::Write;

use common::message_of;

#[test]
fn declared_sizes_over_the_memory_limit_are_refused_before_allocating() {
    volpt_scene::limits::set_memory_limit(1 << 20);
    let dir = tempfile::tempdir().unwrap();

    // A zlib bomb within deflate's ratio: 4 MiB of zeros in a few kilobytes.
    let mut encoder = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
    encoder.write_all(&vec![0u8; 4 << 20]).unwrap();
    let data = encoder.finish().unwrap();
    let mut bytes = format!(
        "NDims = 3\nDimSize = 256 256 64\nElementType = MET_UCHAR\nCompressedData = True\n\
         CompressedDataSize = {}\nElementDataFile = LOCAL\n",
        data.len()
    )
    .into_bytes();
    bytes.extend_from_slice(&data);
    let path = dir.path().join("bomb.mha");
    std::fs::write(&path, bytes).unwrap();
    let err = volpt_scene::read_metaimage(&path).unwrap_err();
    message_of(
        &err,
        &[
            "bomb.mha",
            "256 x 256 x 64",
            "16777216 bytes",
            "memory limit of 1048576",
        ],
    );

    // A .vol whose data is all there, but too much for the limit.
    let grid = common::density_grid([128, 128, 32], common::unit_bounds());
    let path = common::write_grid(dir.path(), "big.vol", &grid);
    let err = volpt_scene::read_vol(&path).unwrap_err();
    message_of(&err, &["big.vol", "128 x 128 x 32", "memory limit"]);

    // Found by fuzzing: an EXR whose header declares tiles so large that the decoder reserved
    // 1.8 GB for one block of a 542-byte file.
    let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/hostile");
    let (_scene_dir, scene) = common::scene_file(&format!(
        "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n\
         <emitter type=\"envmap\"><string name=\"filename\" value=\"{}\"/></emitter>\n\
         <shape type=\"cube\"><bsdf type=\"null\"/>\
         <medium type=\"homogeneous\" name=\"interior\"/></shape>\n</scene>\n",
        fixtures.join("huge-tiles.exr").display()
    ));
    let err = volpt_scene::load_mitsuba(&scene).unwrap_err();
    message_of(
        &err,
        &["huge-tiles.exr", "decoder's blocks", "memory limit"],
    );

    // A small one still loads.
    let grid = common::density_grid([8, 8, 8], common::unit_bounds());
    let path = common::write_grid(dir.path(), "small.vol", &grid);
    volpt_scene::read_vol(&path).expect("within the limit");
}
