//! Mutation property test of the RGL reader and evaluator over the seven real bundled files and
//! two files the project's writer exported (`deepbrdf_data::rgl::export`, a Lambertian and a GGX
//! table): truncations, bit flips, header size fields set to extremes, NaN/inf/huge values in tables,
//! inserted and deleted bytes. Every mutated file must give either a valid evaluator (that then
//! evaluates without panicking) or an error naming the file; never a panic or a huge
//! allocation (every size is checked against the bytes present before allocating).
//!
//! The normal suite runs `DEFAULT_CASES` mutations (a few seconds); set
//! `DEEPBRDF_MUTATIONS=1000000` for a long run (the count and findings are printed).

use deepbrdf_data::rgl::bundled;
use deepbrdf_data::rgl::RglBrdf;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

const DEFAULT_CASES: usize = 2_000;

/// Byte positions of the header's numeric fields: (position, width in bytes).
fn header_fields(b: &[u8]) -> Vec<(usize, usize)> {
    let u16_at = |p: usize| u16::from_le_bytes([b[p], b[p + 1]]) as usize;
    let n = u32::from_le_bytes([b[14], b[15], b[16], b[17]]) as usize;
    let mut out = vec![(14, 4)];
    let mut p = 18;
    for _ in 0..n {
        out.push((p, 2));
        let name_len = u16_at(p);
        p += 2 + name_len;
        out.push((p, 2));
        let rank = u16_at(p);
        out.push((p + 2, 1));
        out.push((p + 3, 8));
        p += 2 + 1 + 8;
        for _ in 0..rank {
            out.push((p, 8));
            p += 8;
        }
    }
    out
}

/// The seed files: the bundled measurements, then the writer's exports. Building them uses rayon:
/// call it first on the test's own thread, never first from a rayon worker (whose pool the
/// build would then wait for).
fn corpus() -> &'static [(String, Vec<u8>)] {
    static CORPUS: OnceLock<Vec<(String, Vec<u8>)>> = OnceLock::new();
    CORPUS.get_or_init(|| {
        use deepbrdf_data::testing::analytic::{ggx, lambertian_table, tabulate, Ggx};
        let lobe = Ggx { alpha: 0.2, f0: [0.9, 0.5, 0.2], diffuse: [0.1; 3] };
        let exports = [
            ("exported lambertian", lambertian_table([0.5, 0.3, 0.1])),
            ("exported ggx", tabulate(|wi, wo| ggx(&lobe, wi, wo))),
        ];
        let resolution = deepbrdf_data::rgl::ExportResolution::default();
        let mut out: Vec<(String, Vec<u8>)> = bundled::files()
            .expect("the bundled files")
            .into_iter()
            .map(|(n, b)| (n.to_string(), b))
            .collect();
        for (name, table) in exports {
            let file = deepbrdf_data::rgl::export(&table, name, &resolution, "e.bsdf")
                .expect("the writer exports the table");
            out.push((name.to_string(), file.to_bytes()));
        }
        out
    })
}

/// Mutation number `case` of one of the files.
fn mutate(case: u64) -> (String, Vec<u8>) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(case);
    let corpus = corpus();
    let (name, original) = &corpus[rng.random_range(0..corpus.len())];
    let original = original.as_slice();
    let mut b = original.to_vec();
    let header_end = 420.min(b.len());
    let kind = rng.random_range(0..6);
    let what = match kind {
        0 => {
            let cut = if rng.random_bool(0.5) {
                rng.random_range(0..header_end)
            } else {
                rng.random_range(0..b.len())
            };
            b.truncate(cut);
            format!("truncated to {cut}")
        }
        1 => {
            let flips = rng.random_range(1..=8);
            for _ in 0..flips {
                let at = if rng.random_bool(0.7) {
                    rng.random_range(0..header_end)
                } else {
                    rng.random_range(0..b.len())
                };
                b[at] ^= 1 << rng.random_range(0..8);
            }
            format!("{flips} bit flips")
        }
        2 => {
            let fields = header_fields(original);
            let (at, width) = fields[rng.random_range(0..fields.len())];
            let extremes: [u64; 9] =
                [0, 1, 2, 3, u64::MAX, u64::MAX / 2, 1 << 31, u32::MAX as u64, b.len() as u64];
            let v = extremes[rng.random_range(0..extremes.len())];
            b[at..at + width].copy_from_slice(&v.to_le_bytes()[..width]);
            format!("field at {at} ({width} bytes) set to {v}")
        }
        3 => {
            let specials = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, -1.0, 0.0, 1e-38];
            let n = rng.random_range(1..=4);
            for _ in 0..n {
                let at = header_end + 4 * rng.random_range(0..(b.len() - header_end) / 4 - 1);
                let v = specials[rng.random_range(0..specials.len())];
                b[at..at + 4].copy_from_slice(&v.to_le_bytes());
            }
            format!("{n} table values set to specials")
        }
        4 => {
            let at = rng.random_range(0..header_end);
            let n = rng.random_range(1..16);
            for _ in 0..n {
                b.insert(at, rng.random());
            }
            format!("{n} bytes inserted at {at}")
        }
        _ => {
            let at = rng.random_range(0..header_end);
            let n = rng.random_range(1..16).min(b.len() - at);
            b.drain(at..at + n);
            format!("{n} bytes deleted at {at}")
        }
    };
    (format!("{name}: {what}"), b)
}

/// Runs one case: `Ok(true)` if the file parsed, `Ok(false)` if it was refused with an error
/// naming it, `Err` for a finding.
fn run_case(case: u64) -> Result<bool, String> {
    let (what, bytes) = mutate(case);
    let path = Path::new("mutated.bsdf");
    let outcome = std::panic::catch_unwind(|| match RglBrdf::parse(path, &bytes) {
        Ok(brdf) => {
            for (a, b) in [(0.1f32, 0.7f32), (1.2, 0.3), (0.0, 1.5), (1.56, 1.56)] {
                let wi = [a.sin(), 0.0, a.cos()];
                let wo = [-b.sin() * 0.6, b.sin() * 0.8, b.cos()];
                let _ = brdf.eval_cos(wi, wo);
                let _ = brdf.pdf(wi, wo);
                let _ = brdf.sample([0.3, 0.8], wi);
            }
            Ok(true)
        }
        Err(e) => {
            let m = e.to_string();
            if m.starts_with("mutated.bsdf: ") {
                Ok(false)
            } else {
                Err(format!("case {case} ({what}): error does not name the file: {m}"))
            }
        }
    });
    outcome.unwrap_or_else(|_| Err(format!("case {case} ({what}): panicked")))
}

#[test]
fn exported_files_parse_unmutated() {
    for (name, bytes) in &corpus()[bundled::names().len()..] {
        RglBrdf::parse(Path::new("e.bsdf"), bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

#[test]
fn mutated_real_files_never_panic() {
    corpus();
    let cases: usize = std::env::var("DEEPBRDF_MUTATIONS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(DEFAULT_CASES);
    let results: Vec<Result<bool, String>> =
        (0..cases as u64).into_par_iter().map(run_case).collect();
    let parsed = results.iter().filter(|r| matches!(r, Ok(true))).count();
    let findings: Vec<&String> = results.iter().filter_map(|r| r.as_ref().err()).collect();
    eprintln!(
        "{cases} mutated inputs: {parsed} parsed, {} refused with an error naming the file, {} findings",
        cases - parsed - findings.len(),
        findings.len()
    );
    assert!(
        findings.is_empty(),
        "{} findings, first: {:?}",
        findings.len(),
        &findings[..findings.len().min(5)]
    );
    // The mutations are not all harmless, nor all fatal: both outcomes occur.
    assert!(parsed > 0 && parsed < cases, "{parsed} of {cases}");
}
