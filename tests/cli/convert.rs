//! CLI tests of `convert` (an RGL `.bsdf` measurement to a MERL `.binary`) and of `.bsdf` paths
//! as materials: the converted file reads back as the table `info` describes from the `.bsdf`
//! path (through the cache), an existing output is not overwritten, a corrupt input is a clean
//! error naming the file.
use crate::util;
use deepbrdf_data::MerlTable;

#[test]
fn convert_writes_a_merl_file_and_bsdf_paths_are_materials() {
    let dir = tempfile::tempdir().expect("tempdir");
    // The bundled measurement as the RGL database's file (the crate holds it compressed).
    let paper = dir.path().join("paper_white_rgb.bsdf");
    let bytes = deepbrdf_data::rgl::bundled::bytes("paper_white_rgb").expect("bundled");
    std::fs::write(&paper, &bytes).expect("write");
    let paper = paper.to_string_lossy().into_owned();
    let paper = paper.as_str();
    let cache = dir.path().join("cache").to_string_lossy().into_owned();
    let out = dir.path().join("paper.binary");
    let out_s = out.to_string_lossy().into_owned();
    let o = util::run(&["convert", paper, "-o", &out_s]);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let text = util::stdout(&o);
    assert!(text.contains("1096216 valid cells") && text.contains("White A4 paper"), "{text}");
    let table = MerlTable::read(&out).expect("a MERL file");
    assert_eq!(table.valid_cells(), 1_096_216);
    // The same material through its .bsdf path (converted and cached) and its bundled name.
    for spec in [paper, "rgl-measured/paper_white_rgb"] {
        let o = util::run(&["info", spec, "--cache", &cache]);
        assert!(o.status.success(), "{}", util::stderr(&o));
        let info = util::stdout(&o);
        assert!(info.contains("RGL") && info.contains("1096216 of 1458000"), "{info}");
    }
    // Converted once: the cache holds one table for the two specs (same bytes, same key).
    let tables = std::fs::read_dir(dir.path().join("cache").join("tables")).expect("cache").count();
    assert_eq!(tables, 1);
    // The output exists now: not overwritten without --force.
    let again = util::run(&["convert", paper, "-o", &out_s]);
    util::assert_clean_failure(&again, "not overwriting");
    // A truncated input: an error naming it.
    let bad = dir.path().join("cut.bsdf");
    std::fs::write(&bad, &bytes[..bytes.len() / 2]).expect("write");
    let bad_s = bad.to_string_lossy().into_owned();
    let o = util::run(&["convert", &bad_s, "-o", &dir.path().join("x.binary").to_string_lossy()]);
    util::assert_clean_failure(&o, "cut.bsdf");
}

/// `export-bsdf`: a MERL file exported reads back through the project's RGL reader; a NaN table,
/// an all-invalid table and an anisotropic request are refused naming the input; an existing
/// output is not overwritten and a refused export leaves no file.
#[test]
fn export_bsdf_writes_a_readable_file_and_refuses_bad_input() {
    use deepbrdf_data::merl::VALUES;
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let good = d.join("grey.binary");
    deepbrdf_data::merl::write_merl(
        &deepbrdf_data::testing::analytic::lambertian_table([0.5; 3]),
        &good,
    )
    .expect("write");
    let out = d.join("grey.bsdf");
    let o = util::run(&["export-bsdf", &util::s(&good), "-o", &util::s(&out)]);
    assert!(o.status.success(), "{}", util::stderr(&o));
    assert!(util::stdout(&o).contains("64 incidence angles"), "{}", util::stdout(&o));
    let brdf = deepbrdf_data::rgl::RglBrdf::read(&out).expect("the project's reader reads it");
    assert_eq!(brdf.description(), "grey");
    let again = util::run(&["export-bsdf", &util::s(&good), "-o", &util::s(&out)]);
    util::assert_clean_failure(&again, "not overwriting");
    let o = util::run(&[
        "export-bsdf",
        &util::s(&good),
        "-o",
        &util::s(&d.join("a.bsdf")),
        "--phi-i",
        "4",
    ]);
    util::assert_clean_failure(&o, "grey.binary");
    // NaN in a stored value: MERL's reader refuses the file, naming it.
    let mut bytes = std::fs::read(&good).expect("read");
    bytes[12 + 8 * 1000..12 + 8 * 1001].copy_from_slice(&f64::NAN.to_le_bytes());
    let nan = d.join("nan.binary");
    std::fs::write(&nan, &bytes).expect("write");
    let o = util::run(&["export-bsdf", &util::s(&nan), "-o", &util::s(&d.join("n.bsdf"))]);
    util::assert_clean_failure(&o, "nan.binary");
    let invalid = d.join("invalid.binary");
    let table = deepbrdf_data::MerlTable::from_values(vec![-1.0; VALUES]).expect("table");
    deepbrdf_data::merl::write_merl(&table, &invalid).expect("write");
    let o = util::run(&["export-bsdf", &util::s(&invalid), "-o", &util::s(&d.join("i.bsdf"))]);
    util::assert_clean_failure(&o, "invalid.binary");
    assert!(!d.join("n.bsdf").exists() && !d.join("i.bsdf").exists() && !d.join("a.bsdf").exists());
}
