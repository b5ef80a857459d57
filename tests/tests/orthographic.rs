//! Mitsuba's `orthographic` sensor, read from Mitsuba 3 XML: looking straight down at a homogeneous
//! slab far wider than its view, every pixel sees the same thing (the same angle onto the same
//! translucent half-space), so the image is uniform over the slab's face: the pixels' means agree
//! within their standard errors (chi-square). The same slab under a wide pinhole is not uniform
//! (oblique views cross more of the slab and reflect more at its surface): the test's control, which shows the
//! statistic can fail.

use volpt_scene::description::Projection;
use volpt_tests::pixel_statistics;

/// The slab (20 x 20 x 0.2 units, extinction 5, albedo 0.5, a dielectric surface of IOR 1.5) in a
/// uniform environment, seen by `sensor`.
fn scene(sensor: &str) -> volpt_scene::SceneDescription {
    let xml = format!(
        r#"<scene version="3.0.0">
    <integrator type="volpath"><integer name="max_depth" value="-1"/></integrator>
    {sensor}
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
    <shape type="cube">
        <transform name="to_world"><scale x="10" y="10" z="0.1"/></transform>
        <bsdf type="dielectric"><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/></bsdf>
        <medium type="homogeneous" name="interior">
            <float name="sigma_t" value="5"/>
            <rgb name="albedo" value="0.5"/>
        </medium>
    </shape>
</scene>"#
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("slab.xml");
    std::fs::write(&path, xml).unwrap();
    volpt_scene::load_mitsuba(&path).unwrap()
}

const FILM: &str = r#"<film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="8"/><rfilter type="box"/></film>"#;

/// Chi-square of the pixels' means (red channel) about their variance-weighted mean, and its
/// degrees of freedom.
fn chi_square(desc: &volpt_scene::SceneDescription) -> (f64, f64) {
    let stats = pixel_statistics(desc, 8192, 3);
    let weight: f64 = stats.iter().map(|p| 1.0 / p[0].1).sum();
    let mean = stats.iter().map(|p| p[0].0 / p[0].1).sum::<f64>() / weight;
    let chi2 = stats.iter().map(|p| (p[0].0 - mean).powi(2) / p[0].1).sum();
    (chi2, stats.len() as f64 - 1.0)
}

/// Chi-square's mean plus five of its standard deviations.
fn bound(dof: f64) -> f64 {
    dof + 5.0 * (2.0 * dof).sqrt()
}

#[test]
fn an_orthographic_view_of_a_homogeneous_slab_is_uniform_over_its_face() {
    let ortho = scene(&format!(
        r#"<sensor type="orthographic">
        <transform name="to_world"><scale value="2"/><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        {FILM}
    </sensor>"#
    ));
    assert_eq!(ortho.camera.projection, Projection::Orthographic);
    let (chi2, dof) = chi_square(&ortho);
    eprintln!("orthographic: chi2 {chi2:.1} over {dof} degrees of freedom");
    assert!(chi2 < bound(dof), "chi2 {chi2:.1}, bound {:.1}", bound(dof));

    let pinhole = scene(&format!(
        r#"<sensor type="perspective">
        <float name="fov" value="120"/>
        <transform name="to_world"><lookat origin="0, 0, 1" target="0, 0, 0" up="0, 1, 0"/></transform>
        {FILM}
    </sensor>"#
    ));
    let (chi2, dof) = chi_square(&pinhole);
    eprintln!("wide pinhole: chi2 {chi2:.1} over {dof} degrees of freedom");
    assert!(
        chi2 > bound(dof),
        "the control should be non-uniform: chi2 {chi2:.1}"
    );
}

#[test]
fn an_orthographic_sensor_takes_no_field_of_view() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.xml");
    let xml = format!(
        r#"<scene version="3.0.0"><sensor type="orthographic"><float name="fov" value="30"/>{FILM}</sensor>
        <shape type="cube"><medium type="homogeneous" name="interior"/></shape></scene>"#
    );
    std::fs::write(&path, xml).unwrap();
    let e = volpt_scene::load_mitsuba(&path).unwrap_err().to_string();
    assert!(
        e.contains("no field of view on an orthographic sensor"),
        "{e}"
    );
}
