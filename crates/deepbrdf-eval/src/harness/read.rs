//! A harness run read back from its folder: the values of `results.csv`, the fit times of
//! `fits.csv` and the settings that `summary.md` states (mode, methods, data, k, seed), all as
//! [`Results::write`] wrote them. What is generated from a run (its charts, the README blocks
//! of `sweep-k`) can so be redrawn, and checked, from the committed files without rerunning.

use super::measures::Measure;
use super::modes::Mode;
use super::report::{FitTiming, Record, Results};
use crate::error::{EvalError, Result};
use std::path::Path;
use std::str::FromStr;

/// The rows of the CSV file `path` below its header, which must be `header`; fields split at
/// commas, a quoted field (RFC 4180, as [`super::csv_field`] writes one) taken whole.
pub(crate) fn csv_rows(path: &Path, header: &str) -> Result<Vec<Vec<String>>> {
    let text = std::fs::read_to_string(path).map_err(|e| EvalError::io(path, e))?;
    let mut lines = text.lines();
    if lines.next() != Some(header) {
        return Err(EvalError::format(path, format!("expected the header {header}")));
    }
    let width = header.split(',').count();
    lines
        .enumerate()
        .map(|(i, line)| {
            let fields = csv_fields(line);
            match fields.len() == width {
                true => Ok(fields),
                false => Err(EvalError::format(
                    path,
                    format!("line {}: {} fields, expected {width}", i + 2, fields.len()),
                )),
            }
        })
        .collect()
}

/// The fields of one CSV line.
fn csv_fields(line: &str) -> Vec<String> {
    let (mut fields, mut field) = (Vec::new(), String::new());
    let (mut quoted, mut chars) = (false, line.chars().peekable());
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(std::mem::take(&mut field)),
            (c, _) => field.push(c),
        }
    }
    fields.push(field);
    fields
}

/// `value` parsed, or an error naming `path` and what it is.
pub(crate) fn parsed<T: FromStr>(path: &Path, what: &str, value: &str) -> Result<T> {
    value.trim().parse().map_err(|_| EvalError::format(path, format!("bad {what} '{value}'")))
}

impl Results {
    /// The run written into `dir` by [`Results::write`]. Methods, measures and k are in the
    /// order the run had them (the methods and k as `summary.md` lists them, the measures in
    /// the order of `results.csv`); the timings not kept in the files read 0.
    pub fn read(dir: &Path) -> Result<Results> {
        let summary_path = dir.join("summary.md");
        let summary =
            std::fs::read_to_string(&summary_path).map_err(|e| EvalError::io(&summary_path, e))?;
        let setting = |prefix: &str| {
            summary.lines().find_map(|l| l.strip_prefix(prefix)).ok_or_else(|| {
                EvalError::format(&summary_path, format!("no line starting '{prefix}'"))
            })
        };
        let mode_line = summary
            .lines()
            .find_map(|l| l.split_once("Reconstruction error: ").map(|(_, m)| m))
            .and_then(|m| m.strip_suffix(" mode"))
            .ok_or_else(|| EvalError::format(&summary_path, "no 'Reconstruction error' line"))?;
        let mode = Mode::from_str(mode_line)?;
        let methods = setting("- methods: ")?.split(", ").map(String::from).collect();
        let (ks, seed) = setting("- k: [")?
            .split_once("], seed: ")
            .ok_or_else(|| EvalError::format(&summary_path, "bad '- k:' line"))?;
        let ks = ks
            .split(", ")
            .map(|k| parsed(&summary_path, "k", k))
            .collect::<Result<Vec<usize>>>()?;
        let seed = parsed(&summary_path, "seed", seed)?;

        let path = dir.join("results.csv");
        let mut records = Vec::new();
        let mut measures: Vec<Measure> = Vec::new();
        for row in csv_rows(&path, "method,k,fold,material,measure,value")? {
            let measure = Measure::from_str(&row[4])?;
            if !measures.contains(&measure) {
                measures.push(measure);
            }
            records.push(Record {
                method: row[0].clone(),
                k: parsed(&path, "k", &row[1])?,
                fold: parsed(&path, "fold", &row[2])?,
                material: row[3].clone(),
                measure,
                value: parsed(&path, "value", &row[5])?,
            });
        }
        let path = dir.join("fits.csv");
        let fits = csv_rows(&path, "method,fold,n_train,seconds")?
            .into_iter()
            .map(|row| {
                Ok(FitTiming {
                    method: row[0].clone(),
                    fold: parsed(&path, "fold", &row[1])?,
                    n_train: parsed(&path, "n_train", &row[2])?,
                    seconds: parsed(&path, "seconds", &row[3])?,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Results {
            mode,
            seed,
            ks,
            methods,
            measures,
            train_label: setting("- training data: ")?.to_string(),
            eval_label: setting("- evaluation data: ")?.to_string(),
            records,
            fits,
            eval_seconds: 0.0,
            total_seconds: 0.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_run_reads_back_the_same() -> Result<()> {
        let mut results = super::super::report::tests::fake_results(7);
        results.records[3].material = "with, a \"comma\"".into();
        let dir = tempfile::tempdir().map_err(|e| EvalError::io("tempdir", e))?;
        results.write(dir.path())?;
        let back = Results::read(dir.path())?;
        assert_eq!(back.records, results.records);
        assert_eq!(back.fits, results.fits);
        assert_eq!((back.mode, back.seed, &back.ks), (results.mode, results.seed, &results.ks));
        assert_eq!((&back.methods, &back.measures), (&results.methods, &results.measures));
        assert_eq!(
            (&back.train_label, &back.eval_label),
            (&results.train_label, &results.eval_label)
        );
        // The same summary tables, so what is generated from them is the same.
        assert_eq!(back.summary_table(), results.summary_table());
        std::fs::write(dir.path().join("fits.csv"), "method,fold\n")
            .map_err(|e| EvalError::io("fits.csv", e))?;
        let e = Results::read(dir.path()).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains("fits.csv") && e.contains("header"), "{e}");
        Ok(())
    }
}
