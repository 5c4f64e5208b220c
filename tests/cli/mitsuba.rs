//! Mitsuba 3 itself renders what `export-bsdf` writes as the project renders the source table:
//! for materials of several kinds (MERL's diffuse, glossy plastic, smooth and rough metals and a
//! fabric with a grazing sheen; a retro-reflective fabric; a blend; an edit), the exported `.bsdf` rendered by Mitsuba's
//! `measured` BSDF (`scripts/mitsuba-render.py`, variant scalar_rgb) and the table rendered by
//! `experiments render`, same sphere, directional light and orthographic camera, differ by image
//! RelAE at most [`BAR`] beyond the Monte Carlo noise (Mitsuba's render with another seed against
//! the first), in two scenes ([`SCENES`]: the sun's view and a grazing one). And the exported
//! file reflects as much light as the table from every direction up to 85 degrees: directional
//! albedo within 2% (`deepbrdf_data::rgl::albedo`).
//!
//! Needs Python with the `mitsuba` package: `$DEEPBRDF_MITSUBA_PYTHON`, else the virtual
//! environment `.venv-mitsuba` at the repository root (`.ci/run` creates it), else `python3`.
//! Without it the test prints why and passes, unless `DEEPBRDF_REQUIRE_MITSUBA=1` (set by
//! `.ci/run`), where its absence is a failure.
use crate::util;
use deepbrdf_data::corpus::retro::Retro;
use deepbrdf_data::merl::MerlTable;
use deepbrdf_data::rgl::albedo::albedo_ratios;
use deepbrdf_eval::metrics::relae;
use deepbrdf_render::Image;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Image RelAE allowed beyond the noise.
const BAR: f64 = 0.005;
const SIZE: &str = "64";
/// The scenes: name, light and camera directions (polar angle from the zenith and azimuth,
/// degrees) and samples per pixel. The grazing one has both at 80 degrees, the light across
/// from the camera; its lit crescent is small, so it takes more samples.
const SCENES: [(&str, &str, &str, &str); 2] =
    [("sun", "40,30", "70,0", "16"), ("grazing", "80,150", "80,0", "1024")];
/// Directional albedo allowed off the table's, relative, at each incidence angle.
const ALBEDO_BAR: f64 = 0.02;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A Python that imports mitsuba with its scalar_rgb variant, or why there is none.
fn mitsuba_python() -> Result<PathBuf, String> {
    let candidates: Vec<PathBuf> = match std::env::var_os("DEEPBRDF_MITSUBA_PYTHON") {
        Some(p) => vec![p.into()],
        None => vec![root().join(".venv-mitsuba/bin/python"), "python3".into()],
    };
    let mut why = Vec::new();
    for python in candidates {
        let probe = Command::new(&python)
            .args(["-c", "import mitsuba; mitsuba.set_variant('scalar_rgb')"])
            .output();
        match probe {
            Ok(o) if o.status.success() => return Ok(python),
            Ok(o) => why.push(format!(
                "{}: {}",
                python.display(),
                String::from_utf8_lossy(&o.stderr).lines().last().unwrap_or("failed")
            )),
            Err(e) => why.push(format!("{}: {e}", python.display())),
        }
    }
    Err(why.join("; "))
}

/// Mitsuba's render of `bsdf` with `seed` under `light`, seen from `view`, with `spp` samples.
fn mitsuba(
    python: &Path,
    bsdf: &Path,
    out: &Path,
    seed: u32,
    [light, view, spp]: [&str; 3],
) -> Image {
    let o = Command::new(python)
        .arg(root().join("scripts/mitsuba-render.py"))
        .args([&util::s(bsdf), &util::s(out), "--size", SIZE, "--spp", spp])
        .args(["--seed", &seed.to_string(), "--light", light, "--view", view])
        .output()
        .expect("running the Mitsuba script");
    assert!(o.status.success(), "mitsuba-render.py: {}", util::stderr(&o));
    Image::read_exr(out).expect("Mitsuba's EXR")
}

/// `0.5 a + 0.5 b` cell by cell (invalid where either is): the linear blend of `interpolate`.
fn blend(a: &MerlTable, b: &MerlTable) -> MerlTable {
    let values = a
        .values()
        .iter()
        .zip(b.values())
        .map(|(x, y)| if *x < 0.0 || *y < 0.0 { -1.0 } else { 0.5 * (x + y) })
        .collect();
    MerlTable::from_values(values).expect("blend")
}

#[test]
fn mitsuba_renders_exported_files_like_the_project() {
    let python = match mitsuba_python() {
        Ok(p) => p,
        Err(why) if std::env::var("DEEPBRDF_REQUIRE_MITSUBA").as_deref() == Ok("1") => {
            panic!("DEEPBRDF_REQUIRE_MITSUBA=1 but no Python imports mitsuba: {why}")
        }
        Err(why) => {
            eprintln!("SKIPPED mitsuba_renders_exported_files_like_the_project: no Python with the mitsuba package ({why}); `.ci/run` installs it");
            return;
        }
    };
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let cache = util::s(&d.join("cache"));
    let run = |args: &[&str]| {
        let o = util::run_in(d, args);
        assert!(o.status.success(), "{args:?}: {}", util::stderr(&o));
        util::stdout(&o)
    };
    // The blend and the edit are written as the commands write them (.binary files).
    let table = |spec: &str| {
        let path = d.join(spec);
        let spec = if path.exists() { util::s(&path) } else { spec.to_string() };
        deepbrdf_data::dataset::load_material(
            &spec,
            &deepbrdf_data::cache::Cache::at(d.join("cache")),
        )
        .expect("material")
        .1
    };
    deepbrdf_data::merl::write_merl(
        &blend(&table("red-plastic"), &table("nickel")),
        d.join("blend.binary"),
    )
    .expect("write blend");
    // A retro-reflective fabric: a Lambertian base and a Lafortune lobe back towards the light.
    let retro = Retro { colour: [0.35, 0.25, 0.3], exponent: 8.0 };
    let fabric = deepbrdf_data::corpus::tabulate(|wi, wo| {
        let lobe = retro.eval(wi, wo);
        let base = [0.3, 0.15, 0.2].map(|a| a / std::f64::consts::PI);
        [0, 1, 2].map(|c| if wi[2] > 0.0 && wo[2] > 0.0 { base[c] + lobe[c] } else { 0.0 })
    })
    .expect("retro-reflective table");
    deepbrdf_data::merl::write_merl(&fabric, d.join("retro.binary")).expect("write retro");
    run(&["edit", "red-plastic", "--roughness-scale", "2", "-o", "edit.binary", "--cache", &cache]);
    let mut worst = f64::NEG_INFINITY;
    for (kind, spec) in [
        ("diffuse", "white-diffuse-bball"),
        ("glossy plastic", "red-plastic"),
        ("metal", "nickel"),
        ("rough metal", "alum-bronze"),
        ("fabric", "pink-fabric"),
        ("retro-reflective fabric", "retro.binary"),
        ("blend", "blend.binary"),
        ("edit", "edit.binary"),
    ] {
        let bsdf = d.join(format!("{kind}.bsdf").replace(' ', "-"));
        run(&["export-bsdf", spec, "-o", &util::s(&bsdf), "--cache", &cache]);
        let angles: Vec<f64> = (0..=17).map(|i| 5.0 * i as f64).collect();
        let file = deepbrdf_data::rgl::RglBrdf::read(&bsdf).expect("the exported file");
        let ratios = albedo_ratios(&table(spec), &file, &angles);
        eprintln!("{kind} ({spec}): albedo file / table at 0, 5, ..., 85 deg {ratios:.3?}");
        for (deg, r) in angles.iter().zip(&ratios) {
            assert!((r - 1.0).abs() <= ALBEDO_BAR, "{kind} ({spec}) at {deg} deg: albedo x{r:.4}");
        }
        for (scene, light, view, spp) in SCENES {
            let exr = d.join("project.exr");
            let dir_light = format!("dir:{light}");
            run(&[
                "render",
                spec,
                "-o",
                "project.png",
                "--exr",
                &util::s(&exr),
                "--light",
                &dir_light,
                "--view",
                view,
                "--size",
                SIZE,
                "--spp",
                spp,
                "--cache",
                &cache,
            ]);
            let project = Image::read_exr(&exr).expect("project EXR");
            let m0 = mitsuba(&python, &bsdf, &d.join("m0.exr"), 0, [light, view, spp]);
            let m1 = mitsuba(&python, &bsdf, &d.join("m1.exr"), 1, [light, view, spp]);
            let noise = relae(&m1, &m0).expect("noise");
            let error = relae(&m0, &project).expect("error");
            eprintln!(
                "{kind} ({spec}), {scene} scene: Mitsuba vs project RelAE {error:.4}, noise {noise:.4}"
            );
            assert!(
                error <= BAR + noise,
                "{kind} ({spec}), {scene} scene: RelAE {error:.4} > {BAR} + noise {noise:.4}"
            );
            worst = worst.max(error - noise);
        }
    }
    eprintln!("worst RelAE beyond noise {worst:.4}");
}
