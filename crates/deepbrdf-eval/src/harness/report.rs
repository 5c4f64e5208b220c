//! The results of a harness run: every (method, k, material, measure) value, fit timings, a
//! markdown summary and the plots (error vs k as in the paper's Fig. 3, per-material error as in
//! Fig. 7).

use super::measures::Measure;
use super::modes::Mode;
use crate::error::{EvalError, Result};
use crate::figures::{write_chart, LineChart, Series};
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
        let v: Vec<f64> = self
            .records
            .iter()
            .filter(|r| r.method == method && r.k == k && r.measure == measure)
            .map(|r| r.value)
            .collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
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
    /// materials.
    pub fn summary_table(&self) -> String {
        let mut s = String::new();
        for &m in &self.measures {
            let _ = writeln!(
                s,
                "Mean {} over {} evaluated materials:\n",
                m.label(),
                self.materials().len()
            );
            let _ = write!(s, "| method |");
            self.ks.iter().for_each(|k| {
                let _ = write!(s, " k = {k} |");
            });
            let _ = write!(s, "\n|---|");
            self.ks.iter().for_each(|_| s.push_str("---:|"));
            s.push('\n');
            for method in &self.methods {
                let _ = write!(s, "| {method} |");
                for &k in &self.ks {
                    match self.mean(method, k, m) {
                        Some(v) => {
                            let _ = write!(s, " {v:.4e} |");
                        }
                        None => s.push_str(" - |"),
                    }
                }
                s.push('\n');
            }
            s.push('\n');
        }
        s
    }

    /// The markdown summary: settings, the tables, fit timings, the plots.
    pub fn summary_markdown(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "# Baselines: {} mode\n", self.mode);
        let _ = writeln!(s, "- training data: {}", self.train_label);
        let _ = writeln!(s, "- evaluation data: {}", self.eval_label);
        let _ = writeln!(s, "- k: {:?}, seed: {}", self.ks, self.seed);
        let _ = writeln!(
            s,
            "- measures over valid cells only; eq. (1) reference = per-value median of the training tables of each fold\n"
        );
        s.push_str(&self.summary_table());
        let _ = writeln!(s, "Fit times (all k from one fit per method and fold):\n");
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
        for &m in &self.measures {
            let _ = writeln!(s, "![{} vs k](error_vs_k_{}.png)\n", m.label(), m.name());
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
        crate::figures::write_atomic_file(&dir.join("results.csv"), csv.as_bytes())?;
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
        crate::figures::write_atomic_file(&dir.join("fits.csv"), fits.as_bytes())?;
        crate::figures::write_atomic_file(
            &dir.join("summary.md"),
            self.summary_markdown().as_bytes(),
        )?;

        let materials = self.materials();
        for &m in &self.measures {
            let series = self
                .methods
                .iter()
                .map(|method| Series {
                    label: method.clone(),
                    points: self
                        .ks
                        .iter()
                        .filter_map(|&k| self.mean(method, k, m).map(|v| (k as f64, v)))
                        .collect(),
                })
                .collect();
            let chart = LineChart {
                title: format!("{} vs k ({})", m.label(), self.mode),
                x_label: "k (dimension of the representation)".into(),
                y_label: format!("mean {}", m.label()),
                log_y: true,
                series,
                categories: None,
                size: (900, 600),
            };
            write_chart(&chart, &dir.join(format!("error_vs_k_{}", m.name())))?;

            let mut series = Vec::new();
            for method in &self.methods {
                for &k in &self.ks {
                    series.push(Series {
                        label: format!("{method} k={k}"),
                        points: self
                            .per_material(method, k, m, &materials)
                            .into_iter()
                            .enumerate()
                            .map(|(i, v)| (i as f64, v))
                            .collect(),
                    });
                }
            }
            let width = (400 + 16 * materials.len() as u32).clamp(900, 2400);
            let chart = LineChart {
                title: format!("{} per material ({})", m.label(), self.mode),
                x_label: "material".into(),
                y_label: m.label().into(),
                log_y: true,
                series,
                categories: Some(materials.clone()),
                size: (width, 760),
            };
            write_chart(&chart, &dir.join(format!("per_material_{}", m.name())))?;
        }
        Ok(())
    }
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}
