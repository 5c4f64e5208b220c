//! The rows of `figures-editing`'s measured suite and their tables: one row per material, edit
//! and method (`suite.csv`), the lobe measures' CSV columns and the lobe summary per
//! representation and mode (`deepbrdf_eval::editing::lobe`).
use deepbrdf_eval::editing::{EditLobe, EditOutcome, LobeBar, LobeTally};
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
/// paper and residual edits and the residual edit carried onto the table (`Space::transfer`),
/// and the edits without a network: analytic, stretch, and stretch on Sun et al. 2018's split
/// (where the suite is given the separation's data).
pub const SUITE_METHODS: [(&str, &str); 9] = [
    ("DeepBRDF", "paper"),
    ("DeepBRDF", "residual"),
    ("DeepBRDF", "transfer"),
    ("IPCA", "paper"),
    ("IPCA", "residual"),
    ("IPCA", "transfer"),
    ("analytic", "-"),
    ("stretch", "-"),
    (SEPARATED, "-"),
];

/// The suite's name of the stretch edit on Sun et al. 2018's split
/// (`deepbrdf_eval::separation::separated_attributes`, then the stretch edit).
pub const SEPARATED: &str = "stretch on Sun2018's split";
