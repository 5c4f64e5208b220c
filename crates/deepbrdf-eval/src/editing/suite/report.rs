//! The edit suite's rows and their tables: one row per material, method, mode and edit
//! (`suite.csv`), the lobe measures' CSV columns, the summary of the re-estimated attributes and
//! the lobe summary per representation and mode ([`crate::editing::lobe`]).
use super::EDITS;
use crate::editing::{EditLobe, EditOutcome, LobeBar, LobeTally};
use crate::stats::{finite_mean, finite_median};
use std::fmt::Write as _;

/// One row of the suite.
pub struct SuiteRow {
    pub material: String,
    pub method: &'static str,
    /// The edit's mode ("paper", "residual"; "-" for the analytic edit).
    pub mode: &'static str,
    pub edit: &'static str,
    pub outcome: EditOutcome,
    pub identity_relae: f64,
    pub plausible: bool,
    pub max_albedo: f64,
    /// The lobe measures; `None` where the original's or the decoded table's lobe is undefined
    /// (no valid cell where it is read).
    pub lobe: Option<EditLobe>,
}

/// The suite's CSV columns of the lobe measures: floor, peak and HWHM ratios, dark hole, the
/// edit's bar, whether it meets it, whether it passes (meets its bar, if any, without a dark
/// hole); empty where the lobe was not measured.
pub fn lobe_columns(lobe: Option<&EditLobe>) -> String {
    let yes = |b: bool| if b { "yes" } else { "no" };
    let Some(l) = lobe else { return ",,,,,,".into() };
    let (c, v) = (l.comparison, l.verdict);
    format!(
        "{:.6},{:.6},{:.6},{},{},{},{}",
        c.floor_ratio,
        c.peak_ratio,
        c.hwhm_ratio,
        yes(c.dark_hole),
        v.bar.map_or("none", LobeBar::key),
        v.meets_bar.map_or("-", yes),
        yes(v.passes())
    )
}

/// The summary's lobe table: per representation and mode, each bar's count (met / held, and
/// passed: met without a dark hole), the dark holes and the edits not measured.
pub fn lobe_summary(rows: &[SuiteRow]) -> String {
    let mut md = String::from("| representation | mode |");
    for bar in LobeBar::ALL {
        let _ = write!(md, " {}: met / held (passed) |", bar.name());
    }
    md += " dark holes | not measured |\n| --- | --- | ---: | ---: | ---: | ---: | ---: |\n";
    for (method, mode) in SUITE_METHODS {
        let sel: Vec<&SuiteRow> =
            rows.iter().filter(|r| r.method == method && r.mode == mode).collect();
        if sel.is_empty() {
            continue;
        }
        let t = LobeTally::of(sel.iter().filter_map(|r| r.lobe.as_ref().map(|l| &l.verdict)));
        let _ = write!(md, "| {method} | {mode} |");
        for c in t.bars {
            let _ = write!(md, " {}/{} ({}) |", c.met, c.held, c.passed);
        }
        let _ = writeln!(md, " {}/{} | {} |", t.dark_holes, t.edits, sel.len() - t.edits);
    }
    md
}

/// The suite's (representation, mode) pairs, in the order of its tables: each representation's
/// paper, residual and nearest latent edits and the residual edit carried onto the table
/// (`Space::transfer`),
/// and the edits without a network: analytic, stretch, parts, and stretch on Sun et al. 2018's
/// split (where the suite is given the separation's data).
pub const SUITE_METHODS: [(&str, &str); 12] = [
    ("DeepBRDF", "paper"),
    ("DeepBRDF", "residual"),
    ("DeepBRDF", "nearest"),
    ("DeepBRDF", "transfer"),
    ("IPCA", "paper"),
    ("IPCA", "residual"),
    ("IPCA", "nearest"),
    ("IPCA", "transfer"),
    ("analytic", "-"),
    ("stretch", "-"),
    ("parts", "-"),
    (SEPARATED, "-"),
];

/// The suite's name of the stretch edit on Sun et al. 2018's split
/// (`deepbrdf_eval::separation::separated_attributes`, then the stretch edit).
pub const SEPARATED: &str = "stretch on Sun2018's split";

/// The CSV of every row (`suite.csv`), with a header line.
pub fn csv(rows: &[SuiteRow]) -> String {
    let mut csv = String::from("material,method,mode,edit,target_error,change_ratio,diffuse_drift,specular_drift,roughness_drift,identity_relae,plausible,max_albedo,floor_ratio,peak_ratio,hwhm_ratio,dark_hole,lobe_bar,meets_bar,lobe_pass\n");
    for r in rows {
        let o = r.outcome;
        let _ = writeln!(
            csv,
            "{},{},{},{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{},{:.6},{}",
            r.material,
            r.method,
            r.mode,
            r.edit,
            o.target_error,
            o.change_ratio,
            o.diffuse_drift,
            o.specular_drift,
            o.roughness_drift,
            r.identity_relae,
            r.plausible,
            r.max_albedo,
            lobe_columns(r.lobe.as_ref())
        );
    }
    csv
}

/// The summary's rows of the re-estimated attributes, per representation, edit and mode:
/// medians over the materials of the target error, change ratio and drifts, the materials
/// within 10% of the target with under 10% drift of every other attribute, the identity
/// edit's mean image RelAE and the plausible tables (columns as `figures-editing` heads them).
pub fn outcome_summary(rows: &[SuiteRow]) -> String {
    let mut md = String::new();
    for method in ["DeepBRDF", "IPCA", "analytic", "stretch", "parts", SEPARATED] {
        for edit_name in EDITS {
            for (_, mode) in SUITE_METHODS.into_iter().filter(|(m, _)| *m == method) {
                let sel: Vec<&SuiteRow> = rows
                    .iter()
                    .filter(|r| r.method == method && r.edit == edit_name && r.mode == mode)
                    .collect();
                if sel.is_empty() {
                    continue;
                }
                let f =
                    |g: fn(&EditOutcome) -> f64| finite_median(sel.iter().map(|r| g(&r.outcome)));
                let good = sel
                    .iter()
                    .filter(|r| {
                        let o = r.outcome;
                        let drifts = [o.diffuse_drift, o.specular_drift, o.roughness_drift];
                        let target_ok = o.target_error.is_nan() || o.target_error < 0.1;
                        target_ok && drifts.iter().all(|d| d.is_nan() || *d < 0.1)
                    })
                    .count();
                let plausible = sel.iter().filter(|r| r.plausible).count();
                let show = |v: f64| if v.is_finite() { format!("{v:.3}") } else { "-".into() };
                let _ = writeln!(
                    md,
                    "| {method} | {edit_name} | {mode} | {} | {} | {} | {} | {} | {good}/{} | {} | {plausible}/{} |",
                    show(f(|o| o.target_error)),
                    show(f(|o| o.change_ratio)),
                    show(f(|o| o.diffuse_drift)),
                    show(f(|o| o.specular_drift)),
                    show(f(|o| o.roughness_drift)),
                    sel.len(),
                    show(finite_mean(sel.iter().map(|r| r.identity_relae))),
                    sel.len()
                );
            }
        }
    }
    md
}
