//! `experiments render`, `compare`, `sheet` and `bench render` on small synthetic MERL files.
use crate::util;
use deepbrdf_data::merl::io::write_merl;
use deepbrdf_data::MerlTable;
use std::path::Path;

/// A plastic-like synthetic material: diffuse `albedo` plus a lobe in theta_h, scaled by `gain`.
fn write_material(path: &Path, albedo: [f32; 3], gain: f32) {
    let table = MerlTable::from_fn(|h, _, _| {
        let th = deepbrdf_data::merl::grid::theta_h_of(h) as f32;
        let lobe = 2.0 * (-(th * th) / 0.02).exp();
        albedo.map(|a| gain * (a / std::f32::consts::PI + lobe))
    });
    write_merl(&table, path).expect("write synthetic material");
}

/// Width and height from a PNG's IHDR chunk (bytes 16..24), after checking the signature.
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).expect("read png");
    assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "{} is not a PNG", path.display());
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    (be(16), be(20))
}

#[test]
fn render_writes_png_and_exr() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mat = dir.path().join("red.binary");
    write_material(&mat, [0.6, 0.1, 0.1], 1.0);
    let out = util::run_in(
        dir.path(),
        &[
            "render",
            "red.binary",
            "-o",
            "red.png",
            "--exr",
            "red.exr",
            "--size",
            "24",
            "--spp",
            "2",
        ],
    );
    assert!(out.status.success(), "{}", util::stderr(&out));
    assert_eq!(png_size(&dir.path().join("red.png")), (24, 24));
    let exr = std::fs::read(dir.path().join("red.exr")).expect("exr");
    assert_eq!(&exr[..4], &[0x76, 0x2f, 0x31, 0x01], "OpenEXR magic number");
    assert!(util::stdout(&out).contains("red"), "{}", util::stdout(&out));
    // Other shapes, lights and a perspective view.
    for extra in [
        &["--shape", "torus", "--light", "dir:30,40", "--fov", "35"][..],
        &["--shape", "plane", "--light", "const", "--view", "40,90"][..],
    ] {
        let mut args =
            vec!["render", "red.binary", "-o", "other.png", "--size", "12", "--spp", "1"];
        args.extend_from_slice(extra);
        let out = util::run_in(dir.path(), &args);
        assert!(out.status.success(), "{extra:?}: {}", util::stderr(&out));
    }
}

#[test]
fn render_rejects_bad_arguments() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mat = dir.path().join("m.binary");
    write_material(&mat, [0.5; 3], 1.0);
    let base = ["render", "m.binary", "-o", "x.png", "--size", "8", "--spp", "1"];
    for (extra, needle) in [
        (&["--light", "lamp:1"][..], "lamp:1"),
        (&["--light", "sun:95,0"][..], "elevation"),
        (&["--view", "45"][..], "--view"),
        (&["--shape", "teapot"][..], "teapot"),
        (&["--exposure", "0"][..], "exposure"),
    ] {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        util::assert_clean_failure(&util::run_in(dir.path(), &args), needle);
    }
    let missing = util::run_in(dir.path(), &["render", "missing.binary", "-o", "x.png"]);
    util::assert_clean_failure(&missing, "missing.binary");
    std::fs::write(dir.path().join("bad.binary"), b"not a brdf").expect("write");
    util::assert_clean_failure(
        &util::run_in(dir.path(), &["render", "bad.binary", "-o", "x.png"]),
        "bad.binary",
    );
    assert!(!dir.path().join("x.png").exists());
}

#[test]
fn compare_prints_relae_and_writes_a_difference_image() {
    let dir = tempfile::tempdir().expect("tempdir");
    write_material(&dir.path().join("a.binary"), [0.3, 0.4, 0.5], 1.0);
    write_material(&dir.path().join("b.binary"), [0.3, 0.4, 0.5], 2.0);
    let args = |b: &'static str| {
        ["compare", "a.binary", b, "-o", "diff.png", "--size", "16", "--spp", "2"]
    };
    let same = util::run_in(dir.path(), &args("a.binary"));
    assert!(same.status.success(), "{}", util::stderr(&same));
    assert!(util::stdout(&same).contains("RelAE 0.0000"), "{}", util::stdout(&same));
    // Twice the reflectance, the same sample directions: every pixel doubles, RelAE = 1.
    let double = util::run_in(dir.path(), &args("b.binary"));
    assert!(double.status.success(), "{}", util::stderr(&double));
    assert!(util::stdout(&double).contains("RelAE 1.0000"), "{}", util::stdout(&double));
    assert_eq!(png_size(&dir.path().join("diff.png")), (16, 16));
}

#[test]
fn sheet_of_a_folder() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = dir.path().join("data");
    std::fs::create_dir(&data).expect("mkdir");
    write_material(&data.join("blue.binary"), [0.1, 0.2, 0.6], 1.0);
    write_material(&data.join("green.binary"), [0.1, 0.6, 0.2], 1.0);
    let out = util::run_in(
        dir.path(),
        &[
            "sheet",
            "--data",
            "data",
            "-o",
            "sheet.png",
            "--size",
            "24",
            "--spp",
            "1",
            "--columns",
            "2",
        ],
    );
    assert!(out.status.success(), "{}", util::stderr(&out));
    assert!(util::stdout(&out).contains("2 materials"), "{}", util::stdout(&out));
    let (w, h) = png_size(&dir.path().join("sheet.png"));
    assert!(w > 48 && h > 24, "{w}x{h}");
}

#[test]
fn bench_render_prints_its_numbers() {
    let dir = tempfile::tempdir().expect("tempdir");
    write_material(&dir.path().join("m.binary"), [0.5; 3], 1.0);
    let out = util::run_in(
        dir.path(),
        &[
            "bench",
            "render",
            "--material",
            "m.binary",
            "--size",
            "8",
            "--spp",
            "1",
            "--repeats",
            "1",
            "--lookups",
            "1000",
        ],
    );
    assert!(out.status.success(), "{}", util::stderr(&out));
    let text = util::stdout(&out);
    for needle in [
        "MERL lookups at random direction pairs (renderer",
        "images/s",
        "M lookups/s in the render",
        "tabulated / analytic",
    ] {
        assert!(text.contains(needle), "{needle}: {text}");
    }
}

#[test]
fn bench_render_noise_prints_noise_and_efficiency() {
    let dir = tempfile::tempdir().expect("tempdir");
    write_material(&dir.path().join("m.binary"), [0.5; 3], 1.0);
    let out = util::run_in(
        dir.path(),
        &[
            "bench",
            "render-noise",
            "--materials",
            "m.binary",
            "--lights",
            "const;sun:40,30",
            "--size",
            "16",
            "--spp",
            "2",
            "--pairs",
            "2",
        ],
    );
    assert!(out.status.success(), "{}", util::stderr(&out));
    let text = util::stdout(&out);
    assert!(text.contains("efficiency") && text.contains("pooled over 2 pairs"), "{text}");
    // One row per material, light and sampler: Lambertian, plastic and the table, under both
    // lights, with the independent and the Sobol sampler.
    let rows: Vec<&str> =
        text.lines().filter(|l| l.contains("const") || l.contains("sun:")).collect();
    assert_eq!(rows.iter().filter(|l| l.starts_with("m ")).count(), 4, "{text}");
    assert_eq!(rows.len(), 12, "{text}");
    for sampler in ["independent", "sobol"] {
        assert_eq!(rows.iter().filter(|l| l.contains(sampler)).count(), 6, "{text}");
    }
    // The Lambertian under the constant environment is exact with either sampler.
    assert!(
        rows.iter()
            .filter(|l| l.starts_with("lambertian") && l.contains("const"))
            .all(|l| l.contains("0.0000")),
        "{text}"
    );
}
