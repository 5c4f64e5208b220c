//! The report of a `sweep-k` run (the paper's Figs. 2, 3 and 7 side by side): the protocol the
//! numbers were measured under, the comparisons the paper claims (DeepBRDF against PCA and
//! IPCA at the same and larger k; against the nearest-slice fill on reduced inputs), the
//! tables, and the DeepBRDF training runs; as `summary.md`, a README block and the printed
//! summary.
use crate::deep::{FitRecord, NAME};
use crate::harness::{Measure, Mode, Results};
use crate::robustness::{self, Robustness, NEAREST_FILL};
use std::fmt::Write as _;

/// `seconds` as minutes and seconds, with the seconds themselves: `2 min 05 s (125.0 s)`.
pub fn minutes(seconds: f64) -> String {
    format!("{:.0} min {:02.0} s ({seconds:.1} s)", (seconds / 60.0).floor(), seconds % 60.0)
}

/// `training.csv`: one row per DeepBRDF fit (fold, k, loaded or trained, seconds, final MSE,
/// model folder).
pub fn training_csv(fits: &[FitRecord]) -> String {
    let mut csv = String::from("fold,k,origin,call_seconds,train_seconds,final_train_mse,dir\n");
    for f in fits {
        let _ = writeln!(
            csv,
            "{},{},{},{:.2},{:.2},{:e},{}",
            f.fold,
            f.k,
            f.origin.name(),
            f.seconds,
            f.train_seconds,
            f.final_mse,
            f.dir.display()
        );
    }
    csv
}

/// Everything the summaries are made of.
pub struct SweepReport<'a> {
    pub results: &'a Results,
    /// The k DeepBRDF was trained and scored at.
    pub deep_ks: &'a [usize],
    pub robustness: &'a Robustness,
    pub fits: &'a [FitRecord],
    pub training: &'a str,
    pub fig2: Option<&'a str>,
    pub loaded_at: f64,
    pub wall: f64,
}

impl SweepReport<'_> {
    /// The measured comparisons: at DeepBRDF's k = 10 (else its first k), its mean of each
    /// measure against PCA's and IPCA's at that k and at every larger k (the paper's Fig. 3 and
    /// 7 claim: DeepBRDF at a small k matches the linear methods at larger ones), then the
    /// paper's Fig. 2 claim on reduced inputs (DeepBRDF against the nearest-slice fill).
    pub fn claims(&self) -> String {
        let mut s = String::new();
        let m = |method: &str, k: usize, measure| self.results.mean(method, k, measure);
        let Some(&k0) = self.deep_ks.iter().find(|&&k| k == 10).or(self.deep_ks.first()) else {
            return s;
        };
        let mut measures = self.results.measures.clone();
        // Image RelAE first: what a rendering shows.
        measures.sort_by_key(|&measure| measure != Measure::ImageRelae);
        for measure in measures {
            let label = measure.label();
            if measure.counts() {
                let c = |method: &str| self.results.count(method, k0, measure);
                if let (Some(d), Some(p), Some(i)) = (c(NAME), c("PCA"), c("IPCA")) {
                    let n = self.results.materials().len();
                    let _ = writeln!(
                        s,
                        "- k = {k0}, {label}: {NAME} {d} vs PCA {p} and IPCA {i} (of {n}): {NAME} has {}.",
                        if d <= p && d <= i { "no more than either" } else { "more than PCA or IPCA" }
                    );
                }
                continue;
            }
            let (Some(d), Some(p), Some(i)) =
                (m(NAME, k0, measure), m("PCA", k0, measure), m("IPCA", k0, measure))
            else {
                continue;
            };
            let _ = writeln!(
                s,
                "- k = {k0}, {label}: {NAME} {d:.4e} vs PCA {p:.4e} and IPCA {i:.4e} ({NAME}/PCA {:.3}, {NAME}/IPCA {:.3}): {NAME} is {} both.",
                d / p,
                d / i,
                if d < i && d < p { "below" } else { "NOT below" }
            );
            for &k in self.results.ks.iter().filter(|&&k| k > k0) {
                if let (Some(p), Some(i)) = (m("PCA", k, measure), m("IPCA", k, measure)) {
                    let _ = writeln!(
                        s,
                        "  - {NAME} at k = {k0} vs PCA and IPCA at k = {k}: {d:.4e} vs {p:.4e} and {i:.4e} ({}).",
                        match (d <= p, d <= i) {
                            (true, true) => "DeepBRDF lower or equal",
                            (true, false) => "below PCA, above IPCA",
                            (false, true) => "below IPCA, above PCA",
                            (false, false) => "both lower",
                        }
                    );
                }
            }
        }
        for &k in &self.robustness.ks {
            for every in robustness::SELECTIONS {
                let fill = self.robustness.mean(every, NEAREST_FILL, None);
                let deep = self.robustness.mean(every, NAME, Some(k));
                if let (Some(f), Some(d)) = (fill, deep) {
                    let _ = writeln!(
                        s,
                        "- 1/{every} of the slices, k = {k}: {NAME} {d:.4e} vs {NEAREST_FILL} {f:.4e}: {NAME} is {}.",
                        if d < f { "better" } else { "NOT better" }
                    );
                }
            }
        }
        s
    }

    /// What the numbers mean: held out, in-sample (memory as much as representation) or on
    /// other collections.
    pub fn protocol(&self) -> String {
        let scored = self.results.materials().len();
        match self.results.mode {
            Mode::KFold { folds } => format!(
                "**Held out**: {folds}-fold over {}; each of the {scored} materials is scored by methods fitted on the other folds only (what a user encoding their own material gets).",
                self.results.train_label
            ),
            Mode::InSample => format!(
                "**In-sample** (the paper's protocol): the {scored} scored materials are the training materials; a network with more parameters than training points can memorise them, so these numbers measure capacity, not how well an unseen material is represented (`--mode kfold:5` does)."
            ),
            Mode::Generalize => format!(
                "**Other collections**: trained on {}, scored on {scored} materials of {} that no method saw.",
                self.results.train_label, self.results.eval_label
            ),
        }
    }

    /// The table of the DeepBRDF fits: fold, k, loaded or trained, seconds, final MSE.
    pub fn training_table(&self) -> String {
        let mut s = String::from(
            "| fold | k | model | training s (recorded) | this run s | final training MSE |\n|---:|---:|---|---:|---:|---:|\n",
        );
        for f in self.fits {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.0} | {:.1} | {:.4e} |",
                f.fold,
                f.k,
                f.origin.name(),
                f.train_seconds,
                f.seconds,
                f.final_mse
            );
        }
        s
    }

    /// `summary.md` of the sweep's folder.
    pub fn summary_markdown(&self) -> String {
        let mut s = String::from("# sweep-k\n\n");
        let _ = writeln!(s, "{}\n", self.protocol());
        let _ = writeln!(s, "DeepBRDF: {}.\n", self.training);
        let _ = writeln!(s, "## Comparisons\n\n{}", self.claims());
        s.push_str(&self.results.summary_markdown().replacen("# ", "## ", 1));
        s.push_str(&self.robustness.markdown(self.results.materials().len(), self.fig2));
        let _ = writeln!(s, "## DeepBRDF training\n\n{}", self.training_table());
        let _ = writeln!(
            s,
            "Data loading {:.1} s; total wall time {}.",
            self.loaded_at,
            minutes(self.wall)
        );
        s
    }

    /// The README block: the mapped-space table, the robustness table, the plots (`link`: the
    /// sweep's folder as seen from the README's folder).
    pub fn readme_block(&self, link: &str) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "Written by `experiments sweep-k` ({} mode, {} materials of {}; DeepBRDF {}; total wall time {}).\n",
            self.results.mode,
            self.results.materials().len(),
            self.results.train_label,
            self.training,
            minutes(self.wall)
        );
        let _ = writeln!(s, "{}\n", self.protocol());
        let _ = writeln!(s, "{}", self.claims());
        if self.results.measures.contains(&Measure::ImageRelae) {
            let _ = writeln!(
                s,
                "Mean image-space RelAE (sphere under sun and sky, Fig. 7's measure):\n"
            );
            s.push_str(&self.results.measure_table(Measure::ImageRelae));
            let _ = writeln!(
                s,
                "\n![per-material image-space RelAE (Fig. 7)]({link}/per_material_image_relae.svg)\n"
            );
        }
        let _ = writeln!(s, "Mean MSE in the eq. (1) mapped space (Fig. 3):\n");
        s.push_str(&self.results.measure_table(Measure::MappedMse));
        let _ = writeln!(s, "\n![error vs k (Fig. 3)]({link}/error_vs_k_mapped_mse.svg)\n");
        let _ = writeln!(s, "![per-material error (Fig. 7)]({link}/per_material_mapped_mse.svg)\n");
        if self.results.measures.contains(&Measure::CosRmse) {
            let _ = writeln!(s, "Mean cosine-weighted RMSE (1/sr):\n");
            s.push_str(&self.results.measure_table(Measure::CosRmse));
            s.push('\n');
        }
        let _ =
            writeln!(s, "Robustness to missing phi_d slices (Fig. 2), mean mapped-space MSE:\n");
        s.push_str(&self.robustness.table());
        let _ = writeln!(s, "\n![robustness (Fig. 2)]({link}/robustness.svg)\n");
        if self.fig2.is_some() {
            let _ = writeln!(s, "![slices (Fig. 2)]({link}/fig2_slices.png)\n");
        }
        let _ = writeln!(s, "Details: [{link}/summary.md]({link}/summary.md).");
        s
    }

    /// What the command prints at the end.
    pub fn printed(&self) -> String {
        let mut s = String::from("\n");
        s.push_str(&self.results.summary_table());
        let _ = writeln!(
            s,
            "Robustness (Fig. 2), mean mapped-space MSE:\n\n{}",
            self.robustness.table()
        );
        let _ = writeln!(s, "DeepBRDF training:\n\n{}", self.training_table());
        let _ = writeln!(s, "{}\n\n{}", self.protocol(), self.claims());
        let _ = writeln!(
            s,
            "Evaluation (encode, decode, measure) {:.1} s; robustness {:.1} s.",
            self.results.eval_seconds, self.robustness.seconds
        );
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deep::FitOrigin;
    use crate::harness::Record;
    use crate::robustness::RobustnessRecord;

    /// Two materials; the means are what the records put there: DeepBRDF 1 at k = 10, PCA and
    /// IPCA 2 and 3 at k = 10, 0.5 and 4 at k = 20.
    fn results() -> Results {
        let mut records = Vec::new();
        let mut add = |method: &str, k: usize, value: f64| {
            for (i, material) in ["a", "b"].into_iter().enumerate() {
                records.push(Record {
                    method: method.into(),
                    k,
                    fold: i,
                    material: material.into(),
                    measure: Measure::MappedMse,
                    // The two materials straddle the mean.
                    value: value * if i == 0 { 0.5 } else { 1.5 },
                });
            }
        };
        add(NAME, 10, 1.0);
        add("PCA", 10, 2.0);
        add("IPCA", 10, 3.0);
        add("PCA", 20, 0.5);
        add("IPCA", 20, 4.0);
        Results {
            mode: Mode::KFold { folds: 2 },
            seed: 0,
            ks: vec![10, 20],
            methods: vec!["PCA".into(), "IPCA".into(), NAME.into()],
            measures: vec![Measure::MappedMse],
            train_label: "two materials".into(),
            eval_label: "two materials".into(),
            records,
            fits: vec![],
            eval_seconds: 1.0,
            total_seconds: 2.0,
        }
    }

    fn robustness() -> Robustness {
        let record = |method: &str, k: Option<usize>, mapped_mse: f64| RobustnessRecord {
            every: robustness::SELECTIONS[0],
            method: method.into(),
            k,
            fold: 0,
            material: "a".into(),
            mapped_mse,
        };
        Robustness {
            ks: vec![10],
            records: vec![record(NEAREST_FILL, None, 2.0), record(NAME, Some(10), 1.0)],
            seconds: 0.5,
        }
    }

    fn fit() -> FitRecord {
        FitRecord {
            fold: 1,
            k: 10,
            dir: "models/fold1/k10".into(),
            origin: FitOrigin::Trained,
            seconds: 12.3,
            train_seconds: 10.0,
            final_mse: 0.25,
        }
    }

    #[test]
    fn claims_compare_deepbrdf_with_the_linear_methods_at_its_k_and_above() {
        let (results, robustness, fits) = (results(), robustness(), [fit()]);
        let report = SweepReport {
            results: &results,
            deep_ks: &[10],
            robustness: &robustness,
            fits: &fits,
            training: "preset slice",
            fig2: None,
            loaded_at: 0.1,
            wall: 125.0,
        };
        let claims = report.claims();
        assert!(claims.contains("DeepBRDF/PCA 0.500, DeepBRDF/IPCA 0.333): DeepBRDF is below both"));
        // A defect is compared as a count of materials.
        let mut holed = results.clone();
        holed.measures.push(Measure::DarkHole);
        for (method, holes) in [(NAME, 2), ("PCA", 0), ("IPCA", 1)] {
            for (i, material) in ["a", "b"].into_iter().enumerate() {
                holed.records.push(Record {
                    method: method.into(),
                    k: 10,
                    fold: i,
                    material: material.into(),
                    measure: Measure::DarkHole,
                    value: f64::from(u8::from(i < holes)),
                });
            }
        }
        let claims_holed = SweepReport { results: &holed, ..report }.claims();
        assert!(
            claims_holed.contains("a dark hole at the highlight: DeepBRDF 2 vs PCA 0 and IPCA 1 (of 2): DeepBRDF has more than PCA or IPCA."),
            "{claims_holed}"
        );
        assert!(claims.contains("vs PCA and IPCA at k = 20: 1.0000e0 vs 5.0000e-1 and 4.0000e0 (below IPCA, above PCA)"), "{claims}");
        assert!(claims.contains("1/3 of the slices, k = 10: DeepBRDF 1.0000e0 vs nearest-slice fill 2.0000e0: DeepBRDF is better."), "{claims}");
        assert!(report.protocol().starts_with("**Held out**: 2-fold over two materials"));
        let block = report.readme_block("results/run");
        assert!(block.contains("](results/run/error_vs_k_mapped_mse.svg)"));
        assert!(block.contains("total wall time 2 min 05 s (125.0 s)"));
        assert!(report.summary_markdown().contains("| 1 | 10 | trained | 10 | 12.3 | 2.5000e-1 |"));
    }

    #[test]
    fn a_method_not_scored_at_a_k_shows_a_dash() {
        let table = results().measure_table(Measure::MappedMse);
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines[0], "| method | k = 10 | k = 20 |");
        assert_eq!(lines[2], "| PCA | 2.0000e0 | 5.0000e-1 |");
        assert_eq!(lines[4], "| DeepBRDF | 1.0000e0 | - |");
    }

    #[test]
    fn the_training_csv_has_one_row_per_fit() {
        let csv = training_csv(&[fit()]);
        assert_eq!(
            csv,
            "fold,k,origin,call_seconds,train_seconds,final_train_mse,dir\n\
             1,10,trained,12.30,10.00,2.5e-1,models/fold1/k10\n"
        );
        assert_eq!(minutes(3600.0), "60 min 00 s (3600.0 s)");
    }
}
