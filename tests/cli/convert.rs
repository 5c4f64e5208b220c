//! CLI tests of `convert` (an RGL `.bsdf` measurement to a MERL `.binary`) and of `.bsdf` paths
//! as materials: the converted file reads back as the table `info` describes from the `.bsdf`
//! path (through the cache), an existing output is not overwritten, a corrupt input is a clean
//! error naming the file.
use crate::util;
use deepbrdf_data::MerlTable;

const PAPER: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../deepbrdf-data/assets/rgl-measured/paper_white_rgb.bsdf"
);

#[test]
fn convert_writes_a_merl_file_and_bsdf_paths_are_materials() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cache = dir.path().join("cache").to_string_lossy().into_owned();
    let out = dir.path().join("paper.binary");
    let out_s = out.to_string_lossy().into_owned();
    let o = util::run(&["convert", PAPER, "-o", &out_s]);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let text = util::stdout(&o);
    assert!(text.contains("1096216 valid cells") && text.contains("White A4 paper"), "{text}");
    let table = MerlTable::read(&out).expect("a MERL file");
    assert_eq!(table.valid_cells(), 1_096_216);
    // The same material through its .bsdf path (converted and cached) and its bundled name.
    for spec in [PAPER, "rgl-measured/paper_white_rgb"] {
        let o = util::run(&["info", spec, "--cache", &cache]);
        assert!(o.status.success(), "{}", util::stderr(&o));
        let info = util::stdout(&o);
        assert!(info.contains("RGL") && info.contains("1096216 of 1458000"), "{info}");
    }
    // Converted once: the cache holds one table for the two specs (same bytes, same key).
    let tables = std::fs::read_dir(dir.path().join("cache").join("tables")).expect("cache").count();
    assert_eq!(tables, 1);
    // The output exists now: not overwritten without --force.
    let again = util::run(&["convert", PAPER, "-o", &out_s]);
    util::assert_clean_failure(&again, "not overwriting");
    // A truncated input: an error naming it.
    let bad = dir.path().join("cut.bsdf");
    let bytes = std::fs::read(PAPER).expect("read");
    std::fs::write(&bad, &bytes[..bytes.len() / 2]).expect("write");
    let bad_s = bad.to_string_lossy().into_owned();
    let o = util::run(&["convert", &bad_s, "-o", &dir.path().join("x.binary").to_string_lossy()]);
    util::assert_clean_failure(&o, "cut.bsdf");
}
