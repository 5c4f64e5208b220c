//! A finished `sweep-k` run read back from its folder (`results.csv`, `fits.csv`,
//! `robustness.csv` and the settings and times `summary.md` states), so its README block
//! ([`SweepReport::readme_block`]) can be regenerated, and checked against the docs, without
//! training or evaluating anything.

use crate::deep::NAME;
use crate::error::{EvalError, Result};
use crate::harness::{parsed, Results};
use crate::robustness::Robustness;
use crate::sweep_report::SweepReport;
use std::path::Path;

/// What a sweep's README block is made of.
pub struct SavedSweep {
    pub results: Results,
    pub robustness: Robustness,
    /// The k DeepBRDF was scored at.
    pub deep_ks: Vec<usize>,
    /// The DeepBRDF training settings, as the summary states them.
    pub training: String,
    /// The run's wall time in seconds, as the summary states it (to 0.1 s).
    pub wall: f64,
    /// Whether the run drew the Fig. 2 slices picture.
    pub fig2: bool,
}

impl SavedSweep {
    /// The sweep written into `dir`.
    pub fn read(dir: &Path) -> Result<Self> {
        let results = Results::read(dir)?;
        let robustness = Robustness::read(dir)?;
        let path = dir.join("summary.md");
        let summary = std::fs::read_to_string(&path).map_err(|e| EvalError::io(&path, e))?;
        let training = summary
            .lines()
            .find_map(|l| l.strip_prefix(&format!("{NAME}: ")))
            .and_then(|t| t.strip_suffix('.'))
            .ok_or_else(|| EvalError::format(&path, format!("no '{NAME}: ' line")))?;
        let wall = summary
            .lines()
            .filter(|l| l.contains("total wall time"))
            .find_map(|l| l.rsplit_once(" (").and_then(|(_, s)| s.strip_suffix(" s).")))
            .ok_or_else(|| EvalError::format(&path, "no 'total wall time ... (S s).' line"))?;
        let mut deep_ks: Vec<usize> =
            results.records.iter().filter(|r| r.method == NAME).map(|r| r.k).collect();
        deep_ks.sort_unstable();
        deep_ks.dedup();
        Ok(Self {
            wall: parsed(&path, "wall time", wall)?,
            training: training.to_string(),
            fig2: dir.join("fig2_slices.png").is_file(),
            results,
            robustness,
            deep_ks,
        })
    }

    /// The report of the run, for its README block (the training runs' own records are not
    /// read back: the block does not show them).
    pub fn report(&self) -> SweepReport<'_> {
        SweepReport {
            results: &self.results,
            deep_ks: &self.deep_ks,
            robustness: &self.robustness,
            fits: &[],
            training: &self.training,
            fig2: self.fig2.then_some(""),
            loaded_at: 0.0,
            wall: self.wall,
        }
    }
}
