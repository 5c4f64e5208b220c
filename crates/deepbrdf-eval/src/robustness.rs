//! Robustness to missing phi_d slices (Hu et al., CGF 2020, §3.2 and Fig. 2): DeepBRDF encodes a
//! BRDF of which only every 3rd or every 9th phi_d slice is known (each missing slice filled
//! from its nearest kept one, "currently, the slices are equally spaced"), and its
//! reconstruction is compared with the filled input itself (the baseline: nearest-slice fill)
//! and with DeepBRDF's reconstruction from the full input.
//!
//! All errors are MSEs in the eq. (1) mapped space over the original's valid cells, with the
//! median of the model's training tables as reference: the harness's [`Yardstick`], so the
//! numbers sit on the same scale as Fig. 3's.

use crate::deep::{DeepMethod, MappedInput, NAME};
use crate::error::{EvalError, Result};
use crate::figures::{write_chart, LineChart, Series};
use crate::harness::{csv_field, csv_rows, parsed, Fold, Measure, Results, Yardstick};
use crate::stats::mean;
use deepbrdf_data::augment::{kept_slices, SliceSelection};
use deepbrdf_data::files::write_atomic;
use deepbrdf_data::table_set::TableSet;
use deepbrdf_data::Progress;
use deepbrdf_model::DeepBrdf;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

/// The label of the baseline in tables and plots.
pub const NEAREST_FILL: &str = "nearest-slice fill";

/// The reduced inputs of Fig. 2: every 3rd and every 9th slice.
pub const SELECTIONS: [usize; 2] = [3, 9];

/// One measured value.
#[derive(Clone, Debug, PartialEq)]
pub struct RobustnessRecord {
    /// Keep every n-th slice (1: the full input).
    pub every: usize,
    /// [`NEAREST_FILL`] or [`NAME`].
    pub method: String,
    /// k of the DeepBRDF model (`None` for the fill baseline).
    pub k: Option<usize>,
    pub fold: usize,
    pub material: String,
    pub mapped_mse: f64,
}

/// All robustness numbers of a run.
#[derive(Clone, Debug, Default)]
pub struct Robustness {
    pub ks: Vec<usize>,
    pub records: Vec<RobustnessRecord>,
    pub seconds: f64,
}

/// Label of an input fraction.
pub fn fraction_label(every: usize) -> String {
    if every == 1 {
        "all slices".into()
    } else {
        format!("1/{every} of the slices")
    }
}

/// Measures, for every fold and each of its evaluated materials, the nearest-fill baseline and
/// DeepBRDF at each of `ks` from the reduced inputs of [`SELECTIONS`]. DeepBRDF's numbers from
/// the full input are taken from the harness's `results` (same models, same yardstick).
#[allow(clippy::too_many_arguments)]
pub fn measure(
    names: &[String],
    tables: &dyn TableSet,
    folds: &[Fold],
    deep: &DeepMethod,
    ks: &[usize],
    results: &Results,
    progress: &dyn Progress,
) -> Result<Robustness> {
    let started = std::time::Instant::now();
    let mut records = Vec::new();
    let kept: Vec<(usize, Vec<usize>)> =
        SELECTIONS.iter().map(|&n| (n, kept_slices(&SliceSelection::Every(n), 0))).collect();
    let steps: usize = folds.iter().map(|f| f.test.len()).sum::<usize>() * SELECTIONS.len();
    progress.start(steps as u64, "Fig. 2 robustness");
    for fold in folds {
        let models: Vec<Arc<DeepBrdf>> = ks
            .iter()
            .map(|&k| {
                deep.model(fold.index, k).ok_or_else(|| {
                    EvalError::Invalid(format!(
                        "no {NAME} model was fitted for fold {} at k = {k}",
                        fold.index
                    ))
                })
            })
            .collect::<Result<_>>()?;
        let Some(first) = models.first() else { break };
        if let Some(m) =
            models.iter().find(|m| m.reference().values() != first.reference().values())
        {
            return Err(EvalError::Invalid(format!(
                "the k = {} and k = {} models of fold {} map with different references",
                first.k(),
                m.k(),
                fold.index
            )));
        }
        let yardstick = Yardstick::from_reference(first.reference().clone());
        for &i in &fold.test {
            let (name, table) = (&names[i], tables.table(i)?);
            let original = yardstick.original(&table);
            // Every model of the fold maps with the fold's reference: map the table once.
            let input = MappedInput::new(&table, first.reference());
            let mut push = |every: usize, method: &str, k: Option<usize>, value: f64| {
                records.push(RobustnessRecord {
                    every,
                    method: method.to_string(),
                    k,
                    fold: fold.index,
                    material: name.clone(),
                    mapped_mse: value,
                })
            };
            for &k in ks {
                let full = results
                    .records
                    .iter()
                    .find(|r| {
                        r.method == NAME
                            && r.k == k
                            && r.measure == Measure::MappedMse
                            && &r.material == name
                    })
                    .map(|r| r.value)
                    .ok_or_else(|| {
                        EvalError::Invalid(format!("no {NAME} result for {name} at k = {k}"))
                    })?;
                push(1, NAME, Some(k), full);
            }
            for (every, kept) in &kept {
                let filled = table.with_kept_slices(kept);
                let value = yardstick.measure(&original, &filled, &[Measure::MappedMse])?[0];
                push(*every, NEAREST_FILL, None, value);
                for model in &models {
                    let recon = input
                        .encode_partial(model, kept)
                        .and_then(|latent| model.decode(&latent))
                        .map_err(|e| EvalError::method(format!("{NAME}-{}", model.k()), e))?;
                    let value = yardstick.measure(&original, &recon, &[Measure::MappedMse])?[0];
                    push(*every, NAME, Some(model.k()), value);
                }
                progress.advance(1);
            }
        }
    }
    progress.finish();
    Ok(Robustness { ks: ks.to_vec(), records, seconds: started.elapsed().as_secs_f64() })
}

impl Robustness {
    /// Mean over materials of the records of (`every`, `method`, `k`).
    pub fn mean(&self, every: usize, method: &str, k: Option<usize>) -> Option<f64> {
        mean(
            self.records
                .iter()
                .filter(|r| r.every == every && r.method == method && r.k == k)
                .map(|r| r.mapped_mse),
        )
    }

    /// The rows of the table: the fill baseline, then DeepBRDF at each k.
    fn rows(&self) -> Vec<(String, &'static str, Option<usize>)> {
        let mut rows = vec![(NEAREST_FILL.to_string(), NEAREST_FILL, None)];
        rows.extend(self.ks.iter().map(|&k| (format!("{NAME} k = {k}"), NAME, Some(k))));
        rows
    }

    /// Columns: the full input, then each reduced one.
    fn columns() -> Vec<usize> {
        std::iter::once(1).chain(SELECTIONS).collect()
    }

    /// The markdown table of mean mapped-space MSEs (rows: methods; columns: inputs). The fill
    /// baseline is exact on the full input (0).
    pub fn table(&self) -> String {
        let mut s = String::from("| input → | all slices |");
        for n in SELECTIONS {
            let _ = write!(s, " 1/{n} of the slices |");
        }
        s.push_str("\n|---|---:|");
        SELECTIONS.iter().for_each(|_| s.push_str("---:|"));
        s.push('\n');
        for (label, method, k) in self.rows() {
            let _ = write!(s, "| {label} |");
            for every in Self::columns() {
                let v =
                    if every == 1 && k.is_none() { Some(0.0) } else { self.mean(every, method, k) };
                match v {
                    Some(v) if v == 0.0 => s.push_str(" 0 (exact) |"),
                    Some(v) => {
                        let _ = write!(s, " {v:.4e} |");
                    }
                    None => s.push_str(" - |"),
                }
            }
            s.push('\n');
        }
        s
    }

    /// The markdown section: what was measured, the table, the plot and the slices figure.
    pub fn markdown(&self, materials: usize, fig2_material: Option<&str>) -> String {
        let mut s = String::from("## Robustness to missing phi_d slices (Fig. 2)\n\n");
        let _ = writeln!(
            s,
            "Mean mapped-space MSE (eq. 1) over {materials} materials. Reduced inputs keep every \
             3rd or 9th phi_d slice (equally spaced, as the paper); each missing slice is filled \
             from its nearest kept one. `{NEAREST_FILL}` is that filled input itself; DeepBRDF \
             encodes the filled input and decodes a full BRDF.\n"
        );
        s.push_str(&self.table());
        let _ = writeln!(s, "\n![Fig. 2 robustness](robustness.svg)\n");
        if let Some(m) = fig2_material {
            let _ = writeln!(s, "![Fig. 2 slices of {m}](fig2_slices.png)\n");
        }
        let _ = writeln!(s, "Robustness evaluation: {:.1} s.\n", self.seconds);
        s
    }

    /// The records written into `dir` by [`Self::write`] (`robustness.csv`); the k are
    /// DeepBRDF's there, the time 0.
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join("robustness.csv");
        let mut records = Vec::new();
        for row in csv_rows(&path, "input,method,k,fold,material,mapped_mse")? {
            let every = row[0].strip_prefix("1/").unwrap_or(&row[0]);
            records.push(RobustnessRecord {
                every: parsed(&path, "input", every)?,
                method: row[1].clone(),
                k: match row[2].is_empty() {
                    true => None,
                    false => Some(parsed(&path, "k", &row[2])?),
                },
                fold: parsed(&path, "fold", &row[3])?,
                material: row[4].clone(),
                mapped_mse: parsed(&path, "mapped_mse", &row[5])?,
            });
        }
        let mut ks: Vec<usize> = records.iter().filter_map(|r| r.k).collect();
        ks.sort_unstable();
        ks.dedup();
        Ok(Self { ks, records, seconds: 0.0 })
    }

    /// Writes `robustness.csv` (every record) and `robustness.svg` into `dir`.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let mut csv = String::from("input,method,k,fold,material,mapped_mse\n");
        for r in &self.records {
            let _ = writeln!(
                csv,
                "1/{},{},{},{},{},{:e}",
                r.every,
                csv_field(&r.method),
                r.k.map(|k| k.to_string()).unwrap_or_default(),
                r.fold,
                csv_field(&r.material),
                r.mapped_mse
            );
        }
        write_atomic(&dir.join("robustness.csv"), csv.as_bytes())?;
        let columns = Self::columns();
        let series = self
            .rows()
            .into_iter()
            .map(|(label, method, k)| Series {
                label,
                points: columns
                    .iter()
                    .enumerate()
                    .filter_map(|(x, &every)| self.mean(every, method, k).map(|v| (x as f64, v)))
                    .collect(),
            })
            .collect();
        let chart = LineChart {
            title: "Reconstruction from a fraction of the phi_d slices (Fig. 2)".into(),
            x_label: "input".into(),
            y_label: Measure::MappedMse.label().into(),
            log_y: true,
            series,
            categories: Some(columns.iter().map(|&n| fraction_label(n)).collect()),
            rotate_categories: false,
            legend_left: true,
            size: (800, 500),
        };
        write_chart(&chart, &dir.join("robustness"))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(
        every: usize,
        method: &str,
        k: Option<usize>,
        material: &str,
        v: f64,
    ) -> RobustnessRecord {
        RobustnessRecord {
            every,
            method: method.into(),
            k,
            fold: 0,
            material: material.into(),
            mapped_mse: v,
        }
    }

    /// Two materials, DeepBRDF at k = 2 from all slices and from 1/3; the fill at 1/3 only.
    fn sample() -> Robustness {
        Robustness {
            ks: vec![2],
            records: vec![
                record(1, NAME, Some(2), "a", 1e-3),
                record(1, NAME, Some(2), "b, coated", 3e-3),
                record(3, NEAREST_FILL, None, "a", 0.5),
                record(3, NEAREST_FILL, None, "b, coated", 0.25),
                record(3, NAME, Some(2), "a", 2e-3),
                record(3, NAME, Some(2), "b, coated", 4e-3),
            ],
            seconds: 1.0,
        }
    }

    #[test]
    fn means_are_over_materials_of_one_cell_of_the_table() {
        let r = sample();
        assert_eq!(r.mean(1, NAME, Some(2)), Some(2e-3));
        assert_eq!(r.mean(3, NEAREST_FILL, None), Some(0.375));
        assert_eq!(r.mean(3, NAME, Some(2)), Some(3e-3));
        assert_eq!(r.mean(9, NAME, Some(2)), None);
        assert_eq!(r.mean(3, NAME, Some(5)), None);
    }

    #[test]
    fn the_table_has_one_row_per_method_and_k_and_marks_exact_and_missing_cells() {
        let table = sample().table();
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines[0], "| input → | all slices | 1/3 of the slices | 1/9 of the slices |");
        assert_eq!(lines[1], "|---|---:|---:|---:|");
        // The fill is exact on the full input; nothing was measured at 1/9.
        assert_eq!(lines[2], format!("| {NEAREST_FILL} | 0 (exact) | 3.7500e-1 | - |"));
        assert_eq!(lines[3], format!("| {NAME} k = 2 | 2.0000e-3 | 3.0000e-3 | - |"));
        assert_eq!(lines.len(), 4);
    }

    #[test]
    fn the_csv_holds_every_record_exactly_and_quotes_fields() {
        let dir = tempfile::tempdir().unwrap();
        let r = sample();
        r.write(dir.path()).unwrap();
        let csv = std::fs::read_to_string(dir.path().join("robustness.csv")).unwrap();
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some("input,method,k,fold,material,mapped_mse"));
        let rows: Vec<&str> = lines.collect();
        assert_eq!(rows.len(), r.records.len());
        for (line, rec) in rows.iter().zip(&r.records) {
            let quoted = line.contains("\"b, coated\"");
            assert_eq!(quoted, rec.material.contains(','), "{line}");
            let value: f64 = line.rsplit(',').next().unwrap().parse().unwrap();
            assert_eq!(value, rec.mapped_mse, "{line}");
            assert!(line.starts_with(&format!("1/{},", rec.every)), "{line}");
            let k = rec.k.map(|k| k.to_string()).unwrap_or_default();
            assert!(line.contains(&format!(",{k},0,")), "{line}");
        }
        assert!(dir.path().join("robustness.svg").is_file());
    }
}
