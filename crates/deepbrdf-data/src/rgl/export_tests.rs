//! Tests of the RGL writer: exported tables read back through the project's own reader and
//! evaluator reproduce the table, and bad tables are refused.

use super::albedo::albedo_ratios;
use super::{export, ExportResolution, RglBrdf, TensorFile};
use crate::merl::grid::CELLS;
use crate::merl::VALUES;
use crate::testing::analytic::{ggx, lambertian_table, tabulate, Ggx};
use crate::MerlTable;
use rand::{Rng, SeedableRng};

fn dir(theta: f64, phi: f64) -> [f64; 3] {
    crate::merl::coords::direction(theta, phi)
}

/// `sum |exported - table| cos_o / sum |table| cos_o` over random direction pairs with both
/// polar angles below `max_deg` (uniform in solid angle).
fn relative_error(table: &MerlTable, brdf: &RglBrdf, max_deg: f64) -> f64 {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let max = max_deg.to_radians();
    let (mut num, mut den) = (0.0, 0.0);
    for _ in 0..20_000 {
        // Uniform in solid angle below max_deg.
        let cos_max = max.cos();
        let ti = rng.random_range(cos_max..1.0f64).acos();
        let to = rng.random_range(cos_max..1.0f64).acos();
        let wi = dir(ti, 0.0);
        let wo = dir(to, rng.random_range(-std::f64::consts::PI..std::f64::consts::PI));
        let want = table.lookup_interpolated(wi, wo);
        let got = brdf.eval_cos(wi.map(|v| v as f32), wo.map(|v| v as f32));
        for c in 0..3 {
            num += (f64::from(got[c]) - f64::from(want[c]) * wo[2]).abs();
            den += f64::from(want[c]) * wo[2];
        }
    }
    num / den
}

fn exported(table: &MerlTable, resolution: &ExportResolution) -> RglBrdf {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("out.bsdf");
    let file = export(table, "a test material", resolution, &path).expect("export");
    file.write(&path).expect("write");
    let back = TensorFile::read(&path).expect("reads back");
    assert_eq!(back.fields(), file.fields());
    for name in ["theta_i", "phi_i", "ndf", "sigma", "vndf", "luminance", "rgb", "valid"] {
        assert!(back.field(name).is_some(), "{name}");
    }
    let brdf = RglBrdf::from_tensor(&back).expect("the project's reader accepts it");
    assert_eq!(brdf.description(), "a test material");
    assert_eq!(brdf.theta_i().len(), resolution.theta_i);
    brdf
}

#[test]
fn exported_tables_read_back_and_reproduce_the_table() {
    let res = ExportResolution::default();
    for ((name, table), tolerance) in analytic_materials().into_iter().zip([0.002, 0.002, 0.002]) {
        let brdf = exported(&table, &res);
        let e = relative_error(&table, &brdf, 75.0);
        eprintln!("{name}: relative error of the exported evaluator {e:.4}");
        assert!(e < tolerance, "{name}: {e}");
    }
}

/// The analytic materials of these tests: a Lambertian, a GGX plastic (alpha 0.15, f0 0.04 with
/// Schlick's Fresnel, so its highlight brightens towards grazing) and a GGX metal (alpha 0.3).
fn analytic_materials() -> [(&'static str, MerlTable); 3] {
    [
        ("lambertian", lambertian_table([0.6, 0.4, 0.2])),
        (
            "plastic",
            tabulate(|wi, wo| {
                ggx(&Ggx { alpha: 0.15, f0: [0.04; 3], diffuse: [0.3, 0.5, 0.2] }, wi, wo)
            }),
        ),
        (
            "metal",
            tabulate(|wi, wo| {
                ggx(&Ggx { alpha: 0.3, f0: [0.9, 0.6, 0.3], diffuse: [0.0; 3] }, wi, wo)
            }),
        ),
    ]
}

/// At the default resolution the file reflects as much light as the table from every direction
/// up to 85 degrees, within 2%.
#[test]
fn exported_tables_keep_their_directional_albedo() {
    let angles: Vec<f64> = (0..=17).map(|i| 5.0 * i as f64).collect();
    for (name, table) in analytic_materials() {
        let brdf = exported(&table, &ExportResolution::default());
        let ratios = albedo_ratios(&table, &brdf, &angles);
        eprintln!("{name}: albedo file / table at 0, 5, ..., 85 deg {ratios:.4?}");
        for (deg, r) in angles.iter().zip(&ratios) {
            assert!((r - 1.0).abs() <= 0.02, "{name} at {deg} deg: {r:.4}");
        }
    }
}

#[test]
fn resolutions_are_options() {
    let table = lambertian_table([0.5; 3]);
    let res = ExportResolution { theta_i: 4, ndf: 32, vndf: 16, rgb: 8 };
    let dir = tempfile::tempdir().expect("tempdir");
    let file = export(&table, "x", &res, dir.path().join("x.bsdf")).expect("export");
    let shape = |n: &str| file.field(n).map(|f| f.shape().to_vec()).unwrap_or_default();
    assert_eq!(shape("theta_i"), [4]);
    assert_eq!(shape("ndf"), [2, 32]);
    assert_eq!(shape("vndf"), [1, 4, 16, 16]);
    assert_eq!(shape("rgb"), [1, 4, 3, 8, 8]);
    assert_eq!(shape("valid"), [4 * 8 * 8 / 8]);
    for bad in [
        ExportResolution { theta_i: 1, ..res },
        ExportResolution { rgb: 100_000, ..res },
        ExportResolution { ndf: 0, ..res },
    ] {
        assert!(export(&table, "x", &bad, "x.bsdf").is_err(), "{bad:?}");
    }
}

#[test]
fn bad_tables_are_refused() {
    let res = ExportResolution { theta_i: 3, ndf: 16, vndf: 8, rgb: 4 };
    let message = |t: &MerlTable| {
        export(t, "x", &res, "x.bsdf").err().map(|e| e.to_string()).unwrap_or_default()
    };
    let invalid = MerlTable::from_values(vec![-1.0; VALUES]).expect("table");
    assert!(message(&invalid).contains("every cell is invalid"), "{}", message(&invalid));
    let black = lambertian_table([0.0; 3]);
    assert!(message(&black).contains("zero at every angle"), "{}", message(&black));
    let mut values = lambertian_table([0.5; 3]).into_values();
    values[CELLS + 1234] = -1.0;
    let mixed = MerlTable::from_values(values).expect("table");
    assert!(message(&mixed).contains("some channels and not others"), "{}", message(&mixed));
    assert!(MerlTable::from_values(vec![f32::NAN; VALUES]).is_err());
}
