//! Training schedules side by side: the loss curves of runs of one network under different
//! settings (initialisation, offset, learning rate, warm-up, batch size), against epochs and
//! against training time, with a table of where each stood at the same epoch and the same
//! time, so that the fastest schedule is shown rather than assumed (issue 57 trains Table 1,
//! §3.2, on a CPU).

use std::fmt::Write as _;
use std::path::Path;

use deepbrdf_data::files::write_atomic;
use deepbrdf_model::train::EpochRecord;

use super::plots::{write_panels_png, LineChart, Series};
use crate::error::{EvalError, Result};

/// One run: its name (the schedule's) and its per-epoch log with seconds.
#[derive(Debug, Clone)]
pub struct ScheduleRun {
    pub name: String,
    /// A few words on its settings, for the table.
    pub settings: String,
    pub log: Vec<EpochRecord>,
}

impl ScheduleRun {
    /// (hours of training at the end of each epoch, loss of that epoch).
    fn by_time(&self) -> Vec<(f64, f64)> {
        let mut hours = 0.0;
        self.log
            .iter()
            .map(|r| {
                hours += r.seconds / 3600.0;
                (hours, r.loss)
            })
            .collect()
    }

    /// (minutes of training at the end of each epoch, loss of that epoch).
    fn by_minutes(&self) -> Vec<(f64, f64)> {
        self.by_time().into_iter().map(|(h, loss)| (60.0 * h, loss)).collect()
    }

    /// The loss of the last epoch finished within `hours` of training.
    fn loss_within(&self, hours: f64) -> Option<f64> {
        self.by_time().into_iter().take_while(|&(t, _)| t <= hours + 1e-9).last().map(|p| p.1)
    }

    fn seconds(&self) -> f64 {
        self.log.iter().map(|r| r.seconds).sum()
    }
}

/// Writes `schedules.png` (loss against epochs and against training time, log scale),
/// `schedules.csv` (every epoch of every run) and `summary.md` (each run at the epochs and
/// time all runs reached) into `out`.
pub fn write_schedules(runs: &[ScheduleRun], out: &Path, note: &str) -> Result<()> {
    if runs.is_empty() || runs.iter().any(|r| r.log.is_empty()) {
        return Err(EvalError::Invalid(
            "every schedule needs at least one finished epoch to compare".into(),
        ));
    }
    std::fs::create_dir_all(out).map_err(|e| EvalError::io(out, e))?;
    let chart = |x_label: &str, series: Vec<Series>| LineChart {
        title: format!("Table 1 training loss by schedule ({x_label})"),
        x_label: x_label.into(),
        y_label: "training loss (eq. 4, mapped space)".into(),
        log_y: true,
        series,
        categories: None,
        rotate_categories: false,
        legend_left: false,
        size: (1000, 520),
    };
    let by_epoch = runs
        .iter()
        .map(|r| Series {
            label: r.name.clone(),
            points: r.log.iter().map(|e| (e.epoch as f64, e.loss)).collect(),
        })
        .collect();
    let by_time =
        runs.iter().map(|r| Series { label: r.name.clone(), points: r.by_minutes() }).collect();
    write_panels_png(
        &[chart("epochs", by_epoch), chart("minutes of training on this machine", by_time)],
        &out.join("schedules"),
    )?;
    let mut csv = String::from("schedule,epoch,loss,learning_rate,seconds\n");
    for r in runs {
        for e in &r.log {
            let _ = writeln!(
                csv,
                "{},{},{:.6e},{:.6e},{:.3}",
                r.name, e.epoch, e.loss, e.learning_rate, e.seconds
            );
        }
    }
    write_atomic(&out.join("schedules.csv"), csv.as_bytes())?;
    write_atomic(&out.join("summary.md"), summary(runs, note).as_bytes())?;
    Ok(())
}

/// The summary table: each run at epochs 1, 5 and the last epoch all reached, and after the
/// training time all reached; the best row of each column in bold.
fn summary(runs: &[ScheduleRun], note: &str) -> String {
    let common = runs.iter().map(|r| r.log.len()).min().unwrap_or(0);
    let common_hours = runs.iter().map(ScheduleRun::seconds).fold(f64::INFINITY, f64::min) / 3600.0;
    let mut epochs: Vec<usize> =
        [1, 5, 10, 20, 50, 100, common].into_iter().filter(|&e| e >= 1 && e <= common).collect();
    epochs.sort_unstable();
    epochs.dedup();
    let mut s = String::from("# Table 1 training schedules\n\n");
    let _ = writeln!(s, "{note}\n");
    let _ = write!(s, "| schedule | settings | epochs | hours | s / epoch |");
    for e in &epochs {
        let _ = write!(s, " loss @ epoch {e} |");
    }
    let _ = writeln!(s, " loss @ {:.2} h |", common_hours);
    let _ = writeln!(s, "|{}", " --- |".repeat(6 + epochs.len()));
    let best_at = |e: usize| runs.iter().map(|r| r.log[e - 1].loss).fold(f64::INFINITY, f64::min);
    let best_time =
        runs.iter().filter_map(|r| r.loss_within(common_hours)).fold(f64::INFINITY, f64::min);
    let cell = |v: Option<f64>, best: f64| match v {
        Some(v) if v == best => format!(" **{v:.4e}** |"),
        Some(v) => format!(" {v:.4e} |"),
        None => " - |".to_string(),
    };
    for r in runs {
        let hours = r.seconds() / 3600.0;
        let _ = write!(
            s,
            "| {} | {} | {} | {hours:.2} | {:.1} |",
            r.name,
            r.settings,
            r.log.len(),
            r.seconds() / r.log.len() as f64
        );
        for &e in &epochs {
            s.push_str(&cell(Some(r.log[e - 1].loss), best_at(e)));
        }
        s.push_str(&cell(r.loss_within(common_hours), best_time));
        s.push('\n');
    }
    s.push_str(
        "\nThe loss is eq. (4)'s on the epoch's training batches (inputs with slice dropout where \
         the schedule has it), averaged over the epoch: [schedules.csv](schedules.csv), \
         ![loss curves](schedules.png)\n",
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(name: &str, losses: &[f64], seconds: f64) -> ScheduleRun {
        ScheduleRun {
            name: name.into(),
            settings: "test".into(),
            log: losses
                .iter()
                .enumerate()
                .map(|(i, &loss)| EpochRecord { epoch: i + 1, loss, learning_rate: 1e-3, seconds })
                .collect(),
        }
    }

    #[test]
    fn the_summary_compares_runs_at_equal_epochs_and_time() {
        // a: 3 epochs of 1 h; b: 6 epochs of 0.5 h. At 3 h a has done 3 epochs, b all 6.
        let a = run("a", &[1.0, 0.5, 0.4], 3600.0);
        let b = run("b", &[2.0, 1.0, 0.8, 0.3, 0.2, 0.1], 1800.0);
        let text = summary(&[a.clone(), b.clone()], "note");
        assert!(text.contains("| a | test | 3 | 3.00 | 3600.0 | **1.0000e0** |"), "{text}");
        assert!(text.contains("loss @ epoch 1 | loss @ epoch 3 | loss @ 3.00 h |"), "{text}");
        assert!(
            text.contains(
                "| b | test | 6 | 3.00 | 1800.0 | 2.0000e0 | 8.0000e-1 | **1.0000e-1** |"
            ),
            "{text}"
        );
        assert_eq!(a.loss_within(1.5), Some(1.0));
        assert_eq!(b.loss_within(1.5), Some(0.8));
        let dir = tempfile::tempdir().unwrap();
        write_schedules(&[a, b], dir.path(), "note").unwrap();
        let png = image::open(dir.path().join("schedules.png")).unwrap();
        assert_eq!((png.width(), png.height()), (1000, 1040));
        let csv = std::fs::read_to_string(dir.path().join("schedules.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + 3 + 6);
        assert!(write_schedules(&[run("empty", &[], 1.0)], dir.path(), "").is_err());
    }
}
