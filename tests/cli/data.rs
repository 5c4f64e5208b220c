//! CLI tests of the data commands: `info`, `tabulate`, `pack-nbrdf`. Each run gets a temporary
//! `--cache`, and at most one material is tabulated per test.
use crate::util;
use deepbrdf_data::merl::io::FILE_BYTES;
use deepbrdf_data::MerlTable;
use std::path::Path;

/// A value printed on the `info` line starting with `label`, column `col`.
fn info_value(text: &str, label: &str, col: usize) -> f64 {
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with(label))
        .unwrap_or_else(|| panic!("no {label} line in {text}"));
    let fields: Vec<&str> = line.trim_start()[label.len()..].split_whitespace().collect();
    fields[col].parse().unwrap_or_else(|_| panic!("bad number in {line}"))
}

fn cache_arg(dir: &Path) -> String {
    dir.join("cache").to_string_lossy().into_owned()
}

#[test]
fn tabulate_one_material_then_info_reads_it_and_matches_the_bundled_one() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cache = cache_arg(dir.path());
    let out = dir.path().join("out");
    let out_s = out.to_string_lossy().into_owned();
    let o = util::run(&["tabulate", "--material", "chrome", "--out", &out_s, "--cache", &cache]);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let file = out.join("chrome.binary");
    assert_eq!(std::fs::metadata(&file).expect("written").len(), FILE_BYTES as u64);
    assert_eq!(FILE_BYTES, 34_992_012);
    assert!(util::stdout(&o).contains("1 new"), "{}", util::stdout(&o));

    let file_s = file.to_string_lossy().into_owned();
    let from_file = util::run(&["info", &file_s, "--cache", &cache]);
    assert!(from_file.status.success(), "{}", util::stderr(&from_file));
    let from_file = util::stdout(&from_file);
    assert!(from_file.contains("34992012 bytes"), "{from_file}");
    assert!(from_file.contains("90 x 90 x 180"), "{from_file}");
    let bundled = util::run(&["info", "merl/chrome", "--cache", &cache]);
    assert!(bundled.status.success(), "{}", util::stderr(&bundled));
    let bundled = util::stdout(&bundled);
    assert!(bundled.contains("bundled NBRDF network"), "{bundled}");
    // The file stores value / MERL_SCALE in f64: the same table to f32 rounding.
    for label in ["median", "max", "albedo"] {
        for c in 0..3 {
            let (a, b) = (info_value(&from_file, label, c), info_value(&bundled, label, c));
            assert!((a - b).abs() <= 1e-5 * b.abs() + 1e-6, "{label} {c}: {a} vs {b}");
        }
    }
    // Chrome reflects part of the light (a metal, not a perfect mirror, nor black).
    let albedo = info_value(&bundled, "albedo", 0);
    assert!(albedo > 0.05 && albedo < 1.5, "{albedo}");
    let valid = info_value(&bundled, "valid cells", 0);
    assert!(valid > 1.0e6 && valid < 1.2e6, "{valid}");

    // Running again leaves the identical file alone; a different file is not overwritten.
    let o = util::run(&["tabulate", "--material", "chrome", "--out", &out_s, "--cache", &cache]);
    assert!(util::stdout(&o).contains("1 unchanged"), "{}", util::stdout(&o));

    // A damaged cache file is not used: it is rebuilt, with a warning naming it and the problem.
    let tables = Path::new(&cache).join("tables");
    let cached: Vec<_> = std::fs::read_dir(&tables).expect("tables").flatten().collect();
    assert_eq!(cached.len(), 1, "{cached:?}");
    let cached = cached[0].path();
    let mut bytes = std::fs::read(&cached).expect("read");
    let last = bytes.len() - 1;
    bytes[last] ^= 0x40;
    std::fs::write(&cached, &bytes).expect("damage");
    let o = util::run(&["info", "merl/chrome", "--cache", &cache]);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let err = util::stderr(&o);
    assert!(err.contains("warning:") && err.contains("checksum mismatch"), "{err}");
    assert!(err.contains(&*cached.to_string_lossy()), "{err}");
    assert_eq!(util::stdout(&o), bundled, "the rebuilt table is the same table");
    let o = util::run(&["info", "merl/chrome", "--cache", &cache]);
    assert!(!util::stderr(&o).contains("warning"), "{}", util::stderr(&o));

    std::fs::write(&file, b"precious user data").expect("write");
    let o = util::run(&["tabulate", "--material", "chrome", "--out", &out_s, "--cache", &cache]);
    util::assert_clean_failure(&o, "--force");
    assert_eq!(std::fs::read(&file).expect("read"), b"precious user data");
    let o = util::run(&[
        "tabulate",
        "--material",
        "chrome",
        "--out",
        &out_s,
        "--cache",
        &cache,
        "--force",
    ]);
    assert!(util::stdout(&o).contains("1 replaced"), "{}", util::stdout(&o));
    assert_eq!(std::fs::metadata(&file).expect("written").len(), FILE_BYTES as u64);
}

#[test]
fn info_of_a_lambertian_file_reports_its_albedo() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("lambert.binary");
    let rho = [0.8f32, 0.5, 0.25];
    MerlTable::from_fn(|_, _, _| rho.map(|r| r / std::f32::consts::PI))
        .write(&path)
        .expect("write");
    let o = util::run(&["info", &path.to_string_lossy(), "--cache", &cache_arg(dir.path())]);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let text = util::stdout(&o);
    for c in 0..3 {
        let a = info_value(&text, "albedo", c);
        assert!((a - rho[c] as f64).abs() < 2e-3, "channel {c}: {a} in {text}");
    }
    let valid = info_value(&text, "valid cells", 0);
    assert!(valid > 1.0e6, "{text}");
}

#[test]
fn info_fails_cleanly_on_bad_input() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cache = cache_arg(dir.path());
    let missing = dir.path().join("missing.binary");
    let o = util::run(&["info", &missing.to_string_lossy(), "--cache", &cache]);
    util::assert_clean_failure(&o, "missing.binary");

    let empty = dir.path().join("empty.binary");
    std::fs::write(&empty, b"").expect("write");
    let o = util::run(&["info", &empty.to_string_lossy(), "--cache", &cache]);
    util::assert_clean_failure(&o, "empty.binary");

    let truncated = dir.path().join("truncated.binary");
    let mut bytes = Vec::new();
    for d in [90i32, 90, 180] {
        bytes.extend(d.to_le_bytes());
    }
    bytes.extend(vec![0u8; 1000]);
    std::fs::write(&truncated, &bytes).expect("write");
    let o = util::run(&["info", &truncated.to_string_lossy(), "--cache", &cache]);
    util::assert_clean_failure(&o, "truncated.binary");

    let o = util::run(&["info", &dir.path().to_string_lossy(), "--cache", &cache]);
    util::assert_clean_failure(&o, "directory");

    let o = util::run(&["info", "chrom", "--cache", &cache]);
    util::assert_clean_failure(&o, "merl/chrome");
}

#[test]
fn info_lists_the_159_bundled_materials() {
    let o = util::run(&["info", "--list"]);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let text = util::stdout(&o);
    let count = |prefix: &str| text.lines().filter(|l| l.starts_with(prefix)).count();
    assert_eq!((count("merl/"), count("nielsen2015/"), count("rgl/")), (100, 8, 51));
}

#[test]
fn pack_nbrdf_packs_json_folders_reproducibly_and_rejects_bad_networks() {
    let dir = tempfile::tempdir().expect("tempdir");
    let src = dir.path().join("json");
    // One small network per collection, made from the bundled ones.
    let layer = |inputs: usize, outputs: usize, seed: f64| {
        let weight: Vec<Vec<f64>> = (0..outputs)
            .map(|o| (0..inputs).map(|i| ((o * 7 + i) as f64 * seed).sin() * 0.2).collect())
            .collect();
        serde_json::json!({"in": inputs, "out": outputs, "weight": weight, "bias": vec![0.1; outputs]})
    };
    for (folder, name) in [("merl", "m1"), ("nielsen2015", "n1"), ("rgl-isotropic", "r1")] {
        std::fs::create_dir_all(src.join(folder)).expect("mkdir");
        let net = serde_json::json!({"name": name, "collection": folder,
            "layers": [layer(6, 21, 0.3), layer(21, 21, 0.7), layer(21, 3, 1.1)]});
        std::fs::write(src.join(folder).join(format!("{name}.json")), net.to_string())
            .expect("write");
    }
    let out = dir.path().join("packs");
    let args = ["pack-nbrdf", "--from", &src.to_string_lossy(), "--out", &out.to_string_lossy()]
        .map(String::from);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = util::run(&args);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let first = std::fs::read(out.join("merl.nbrdf")).expect("packed");
    // Header (48 bytes) + name length (2) + "m1" + 675 f32.
    assert_eq!(first.len(), 48 + 2 + 2 + 675 * 4);
    let networks = deepbrdf_data::nbrdf::unpack(&first, &out).expect("unpack");
    assert_eq!(networks[0].name(), "m1");
    let o = util::run(&args);
    assert!(util::stdout(&o).contains("(unchanged)"), "{}", util::stdout(&o));
    assert_eq!(std::fs::read(out.join("merl.nbrdf")).expect("packed"), first);

    let bad = serde_json::json!({"name": "r2", "collection": "rgl",
        "layers": [layer(6, 21, 0.3), layer(21, 20, 0.7), layer(20, 3, 1.1)]});
    std::fs::write(src.join("rgl-isotropic/r2.json"), bad.to_string()).expect("write");
    let o = util::run(&args);
    util::assert_clean_failure(&o, "r2.json");
    util::assert_clean_failure(&o, "layer 2 is 21->20");
}
