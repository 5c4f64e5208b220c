//! The results of a harness run: every (method, k, material, measure) value, fit timings, a
//! markdown summary and the plots (error vs k as in the paper's Fig. 3, per-material error as in
//! Fig. 7).

use super::measures::Measure;
use super::modes::Mode;
use crate::error::{EvalError, Result};
use crate::figures::{write_chart, write_panels, LineChart, Series};
use crate::stats::mean;
use std::fmt::Write as _;
use std::path::Path;

/// One measured value.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    pub method: String,
    pub k: usize,
    pub fold: usize,
    pub material: String,
    pub measure: Measure,
    pub value: f64,
}

/// Time spent fitting one method in one fold (all k at once where the method allows).
#[derive(Clone, Debug, PartialEq)]
pub struct FitTiming {
    pub method: String,
    pub fold: usize,
    pub n_train: usize,
    pub seconds: f64,
}

/// Everything a run produced.
#[derive(Clone, Debug)]
pub struct Results {
    pub mode: Mode,
    pub seed: u64,
    pub ks: Vec<usize>,
    pub methods: Vec<String>,
    pub measures: Vec<Measure>,
    /// Human description of the training and evaluation data.
    pub train_label: String,
    pub eval_label: String,
    pub records: Vec<Record>,
    pub fits: Vec<FitTiming>,
    /// Seconds spent encoding, decoding and measuring.
    pub eval_seconds: f64,
    pub total_seconds: f64,
}

impl Results {
    /// Mean of `measure` over all evaluated materials (all folds) for `method` at `k`.
    pub fn mean(&self, method: &str, k: usize, measure: Measure) -> Option<f64> {
        mean(
            self.records
                .iter()
                .filter(|r| r.method == method && r.k == k && r.measure == measure)
                .map(|r| r.value),
        )
    }

    /// Per-material values of `measure` for `method` at `k`, in `materials` order.
    pub fn per_material(
        &self,
        method: &str,
        k: usize,
        measure: Measure,
        materials: &[String],
    ) -> Vec<f64> {
        materials
            .iter()
            .map(|m| {
                self.records
                    .iter()
                    .find(|r| {
                        r.method == method && r.k == k && r.measure == measure && &r.material == m
                    })
                    .map_or(f64::NAN, |r| r.value)
            })
            .collect()
    }

    /// Evaluated material names, in first-seen order.
    pub fn materials(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for r in &self.records {
            if !out.contains(&r.material) {
                out.push(r.material.clone());
            }
        }
        out
    }

    /// A markdown table per measure: one row per method, one column per k, the mean over
    /// materials (for a defect count, [`Measure::counts`], the number of materials).
    pub fn summary_table(&self) -> String {
        let mut s = String::new();
        for &m in &self.measures {
            let n = self.materials().len();
            let _ = match m.counts() {
                true => writeln!(s, "Number of {} (of {n} evaluated materials):\n", m.label()),
                false => writeln!(s, "Mean {} over {n} evaluated materials:\n", m.label()),
            };
            s.push_str(&self.measure_table(m));
            s.push('\n');
        }
        s
    }

    /// How many materials `method` at `k` has with the defect `measure` ([`Measure::counts`]);
    /// `None` where it was not scored.
    pub fn count(&self, method: &str, k: usize, measure: Measure) -> Option<usize> {
        let values: Vec<f64> = self
            .records
            .iter()
            .filter(|r| r.method == method && r.k == k && r.measure == measure)
            .map(|r| r.value)
            .collect();
        (!values.is_empty()).then(|| values.iter().filter(|&&v| v > 0.5).count())
    }

    /// The markdown table of one measure: one row per method, one column per k, the mean over
    /// materials, or the count for a defect (`-` where a method was not scored at a k).
    pub fn measure_table(&self, measure: Measure) -> String {
        let mut s = String::from("| method |");
        self.ks.iter().for_each(|k| {
            let _ = write!(s, " k = {k} |");
        });
        s.push_str("\n|---|");
        self.ks.iter().for_each(|_| s.push_str("---:|"));
        s.push('\n');
        for method in &self.methods {
            let _ = write!(s, "| {method} |");
            for &k in &self.ks {
                let cell = match measure.counts() {
                    true => self.count(method, k, measure).map(|c| c.to_string()),
                    false => self.mean(method, k, measure).map(|v| format!("{v:.4e}")),
                };
                let _ = write!(s, " {} |", cell.as_deref().unwrap_or("-"));
            }
            s.push('\n');
        }
        s
    }

    /// The markdown summary: settings, the tables, fit timings, the plots.
    pub fn summary_markdown(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "# Reconstruction error: {} mode\n", self.mode);
        let _ = writeln!(s, "- methods: {}", self.methods.join(", "));
        let _ = writeln!(s, "- training data: {}", self.train_label);
        let _ = writeln!(s, "- evaluation data: {}", self.eval_label);
        let _ = writeln!(s, "- k: {:?}, seed: {}", self.ks, self.seed);
        let _ = writeln!(
            s,
            "- measures over valid cells only; eq. (1) reference = per-value median of the training tables of each fold\n"
        );
        s.push_str(&self.summary_table());
        let _ = writeln!(
            s,
            "Fit times (per method and fold, all k; PCA and IPCA fit once for all k):\n"
        );
        let _ =
            writeln!(s, "| method | fold | training materials | seconds |\n|---|---:|---:|---:|");
        for f in &self.fits {
            let _ = writeln!(s, "| {} | {} | {} | {:.2} |", f.method, f.fold, f.n_train, f.seconds);
        }
        let _ = writeln!(
            s,
            "\nEncoding + decoding + measuring: {:.1} s; whole run: {:.1} s.\n",
            self.eval_seconds, self.total_seconds
        );
        for &m in self.measures.iter().filter(|m| !m.counts()) {
            let _ = writeln!(s, "![{} vs k](error_vs_k_{}.svg)\n", m.label(), m.name());
            let _ = writeln!(s, "![{} per material](per_material_{}.svg)\n", m.label(), m.name());
        }
        s
    }

    /// Writes `results.csv`, `fits.csv`, `summary.md` and the plots into `dir` (created if
    /// needed; files of the same names are replaced, each through a temp file and a rename).
    pub fn write(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|e| EvalError::io(dir, e))?;
        let mut csv = String::from("method,k,fold,material,measure,value\n");
        for r in &self.records {
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{:e}",
                csv_field(&r.method),
                r.k,
                r.fold,
                csv_field(&r.material),
                r.measure.name(),
                r.value
            );
        }
        deepbrdf_data::files::write_atomic(&dir.join("results.csv"), csv.as_bytes())?;
        let mut fits = String::from("method,fold,n_train,seconds\n");
        for f in &self.fits {
            let _ = writeln!(
                fits,
                "{},{},{},{:.3}",
                csv_field(&f.method),
                f.fold,
                f.n_train,
                f.seconds
            );
        }
        deepbrdf_data::files::write_atomic(&dir.join("fits.csv"), fits.as_bytes())?;
        deepbrdf_data::files::write_atomic(
            &dir.join("summary.md"),
            self.summary_markdown().as_bytes(),
        )?;
        self.write_charts(dir)
    }

    /// Writes the plots into `dir`: error vs k and per material, one of each per error measure
    /// (the defect counts are in the summary's tables).
    pub fn write_charts(&self, dir: &Path) -> Result<()> {
        for &m in self.measures.iter().filter(|m| !m.counts()) {
            write_chart(&self.error_vs_k_chart(m), &dir.join(format!("error_vs_k_{}", m.name())))?;
            write_panels(
                &self.per_material_charts(m),
                &dir.join(format!("per_material_{}", m.name())),
            )?;
        }
        Ok(())
    }

    /// Fig. 3: the mean of `measure` against k, one line per method, log scale. The k values
    /// are evenly spaced categories (the usual 5, 10, 20, 40 double at each step).
    pub fn error_vs_k_chart(&self, measure: Measure) -> LineChart {
        let series = self
            .methods
            .iter()
            .map(|method| Series {
                label: method.clone(),
                points: self
                    .ks
                    .iter()
                    .enumerate()
                    .filter_map(|(i, &k)| self.mean(method, k, measure).map(|v| (i as f64, v)))
                    .collect(),
            })
            .collect();
        LineChart {
            title: format!("{} vs k ({}, {})", measure.label(), self.mode, self.eval_label),
            x_label: "k (dimension of the representation)".into(),
            y_label: format!("mean {}", measure.label()),
            log_y: true,
            series,
            categories: Some(self.ks.iter().map(|k| k.to_string()).collect()),
            rotate_categories: false,
            legend_left: false,
            size: (900, 600),
        }
    }

    /// The k at which every method was scored (all k if there is none): the k of the
    /// per-material panels, where the methods can be compared (each method's values at every
    /// k are in `results.csv`, its means in the tables and in error vs k).
    pub fn shared_ks(&self) -> Vec<usize> {
        let scored = |method: &String, k: usize| {
            self.records.iter().any(|r| &r.method == method && r.k == k)
        };
        let shared: Vec<usize> = self
            .ks
            .iter()
            .copied()
            .filter(|&k| self.methods.iter().all(|m| scored(m, k)))
            .collect();
        if shared.is_empty() {
            self.ks.clone()
        } else {
            shared
        }
    }

    /// Fig. 7: per-material values of `measure`, one panel per k at which every method was
    /// scored ([`Self::shared_ks`]), one line per method; in each panel the materials are
    /// sorted by the geometric mean of the methods' values at that k, so the panel reads from
    /// the easiest material to the hardest and the lines can be compared material by material.
    pub fn per_material_charts(&self, measure: Measure) -> Vec<LineChart> {
        let materials = self.materials();
        let width = (300 + 14 * materials.len() as u32).clamp(900, 2600);
        self.shared_ks()
            .iter()
            .map(|&k| {
                let values: Vec<Vec<f64>> = self
                    .methods
                    .iter()
                    .map(|method| self.per_material(method, k, measure, &materials))
                    .collect();
                let mut order: Vec<usize> = (0..materials.len()).collect();
                let key = |i: usize| {
                    let logs: Vec<f64> = values
                        .iter()
                        .map(|v| v[i])
                        .filter(|v| v.is_finite() && *v > 0.0)
                        .map(f64::ln)
                        .collect();
                    if logs.is_empty() {
                        f64::INFINITY
                    } else {
                        logs.iter().sum::<f64>() / logs.len() as f64
                    }
                };
                order.sort_by(|&a, &b| key(a).total_cmp(&key(b)));
                let series = self
                    .methods
                    .iter()
                    .zip(&values)
                    .map(|(method, v)| Series {
                        label: format!("{method}, k = {k}"),
                        points: order.iter().enumerate().map(|(x, &i)| (x as f64, v[i])).collect(),
                    })
                    .collect();
                LineChart {
                    title: format!(
                        "{} per material, k = {k} ({}, {}; sorted by the methods' geometric mean)",
                        measure.label(),
                        self.mode,
                        self.eval_label
                    ),
                    x_label: "material".into(),
                    y_label: measure.label().into(),
                    log_y: true,
                    series,
                    categories: Some(order.iter().map(|&i| materials[i].clone()).collect()),
                    rotate_categories: true,
                    legend_left: true,
                    size: (width, 640),
                }
            })
            .collect()
    }
}

/// A CSV field, quoted when it holds a comma, a quote or a line break (RFC 4180).
pub(crate) fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Results shaped like a DeepBRDF sweep: 3 methods x 4 k x `n` materials, two measures.
    pub(crate) fn fake_results(n: usize) -> Results {
        let methods = ["PCA", "IPCA", "DeepBRDF"];
        let ks = vec![5, 10, 20, 40];
        let mut records = Vec::new();
        for (mi, method) in methods.iter().enumerate() {
            for &k in &ks {
                for i in 0..n {
                    for measure in Measure::TABLE {
                        let hardness = 1.0 + ((i * 37) % n) as f64 / n as f64 * 20.0;
                        let value = hardness * 1e-2 / (1.0 + mi as f64) / k as f64;
                        records.push(Record {
                            method: method.to_string(),
                            k,
                            fold: i % 5,
                            material: format!("material-{i:03}"),
                            measure,
                            value,
                        });
                    }
                }
            }
        }
        Results {
            mode: Mode::KFold { folds: 5 },
            seed: 3,
            ks,
            methods: methods.iter().map(|m| m.to_string()).collect(),
            measures: Measure::TABLE.to_vec(),
            train_label: "fake (100)".into(),
            eval_label: "fake (100)".into(),
            records,
            fits: vec![FitTiming { method: "PCA".into(), fold: 0, n_train: 80, seconds: 1.5 }],
            eval_seconds: 1.0,
            total_seconds: 2.5,
        }
    }

    #[test]
    fn defects_are_counted_per_method_and_k_and_drawn_in_no_chart() {
        let mut results = fake_results(10);
        for (i, r) in results.records.clone().iter().enumerate() {
            if r.measure == Measure::MappedMse {
                let hole = (r.method == "IPCA" && r.k == 5 && i % 3 == 0) as u8;
                results.records.push(Record {
                    measure: Measure::DarkHole,
                    value: f64::from(hole),
                    ..r.clone()
                });
            }
        }
        results.measures.push(Measure::DarkHole);
        assert_eq!(results.count("PCA", 5, Measure::DarkHole), Some(0));
        let holes = results.count("IPCA", 5, Measure::DarkHole).unwrap_or(0);
        assert!(holes > 0 && holes < 10, "{holes}");
        let table = results.measure_table(Measure::DarkHole);
        assert!(table.contains(&format!("| IPCA | {holes} | 0 | 0 | 0 |")), "{table}");
        let summary = results.summary_markdown();
        assert!(summary.contains("Number of materials decoded with a dark hole at the highlight (of 10 evaluated materials)"), "{summary}");
        assert!(!summary.contains("error_vs_k_dark_hole"), "{summary}");
    }

    #[test]
    fn three_methods_four_ks_hundred_materials_make_readable_figures() {
        let results = fake_results(100);
        assert_eq!(results.mean("DeepBRDF", 40, Measure::MappedMse).map(|v| v > 0.0), Some(true));
        // Fig. 7: one panel per k, one line per method, materials sorted by error.
        let panels = results.per_material_charts(Measure::MappedMse);
        assert_eq!(panels.len(), 4);
        for (panel, k) in panels.iter().zip([5, 10, 20, 40]) {
            assert_eq!(panel.series.len(), 3);
            assert!(panel.title.contains(&format!("k = {k}")));
            let names = panel.categories.as_ref().map_or(0, |c| c.len());
            assert_eq!(names, 100);
            // Every method's values increase along the sorted axis in this fake data (they are
            // proportional to one another), so sorting by the geometric mean sorts each.
            for s in &panel.series {
                assert!(s.points.windows(2).all(|w| w[0].1 <= w[1].1), "{}", s.label);
            }
        }
        let chart = results.error_vs_k_chart(Measure::CosRmse);
        assert_eq!(chart.series.len(), 3);
        assert_eq!(chart.categories, Some(vec!["5".into(), "10".into(), "20".into(), "40".into()]));

        let dir = tempfile::tempdir().unwrap();
        results.write(dir.path()).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("per_material_mapped_mse.svg")).unwrap();
        assert!(svg.contains(r#"width="1700" height="2560""#), "{}", &svg[..200.min(svg.len())]);
        let md = std::fs::read_to_string(dir.path().join("summary.md")).unwrap();
        assert!(md.contains("| DeepBRDF |") && md.contains("per_material_cos_rmse.svg"), "{md}");
        let csv = std::fs::read_to_string(dir.path().join("results.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + 3 * 4 * 100 * 2);
        // Rewriting into the same folder replaces the files and leaves no temporary file.
        results.write(dir.path()).unwrap();
        let leftovers: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
    }
}
