//! `experiments figures-schedules RUNS --out DIR`: the loss curves of the training runs in
//! RUNS (one folder per schedule, as `scripts/table1-schedules.sh` trains them), against epochs
//! and against training time, in one PNG with a CSV and a summary table
//! ([`deepbrdf_eval::figures::schedules`]).
use anyhow::Context;
use deepbrdf_data::Progress;
use deepbrdf_eval::figures::schedules::{write_schedules, ScheduleRun};
use deepbrdf_model::train::{checkpoint_path, saved_log};
use deepbrdf_model::TrainConfig;
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// A folder of run folders (each with train_config.json and the checkpoint `train` keeps).
    pub runs: PathBuf,
    /// Output folder (schedules.png, schedules.csv, summary.md).
    #[arg(long, value_name = "DIR", default_value = "results/table1-cpu/schedules")]
    pub out: PathBuf,
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let mut folders: Vec<PathBuf> = std::fs::read_dir(&args.runs)
        .with_context(|| format!("{}: cannot list the runs", args.runs.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| checkpoint_path(p).is_file())
        .collect();
    folders.sort();
    if folders.is_empty() {
        anyhow::bail!("{}: no run folder with a checkpoint in it", args.runs.display());
    }
    let runs = folders.iter().map(|f| schedule_run(f)).collect::<anyhow::Result<Vec<_>>>()?;
    let note = format!(
        "Runs in `{}`, written by `experiments figures-schedules {} --out {}` ({} threads).",
        args.runs.display(),
        args.runs.display(),
        args.out.display(),
        rayon::current_num_threads()
    );
    write_schedules(&runs, &args.out, &note)?;
    for r in &runs {
        let last = r.log.last().map_or(f64::NAN, |e| e.loss);
        println!("{:28} {:4} epochs, last loss {last:.4e}", r.name, r.log.len());
    }
    println!("wrote {}", args.out.join("summary.md").display());
    Ok(())
}

/// The run in `folder`: its name, its settings in a few words and its log with seconds.
fn schedule_run(folder: &Path) -> anyhow::Result<ScheduleRun> {
    let config = TrainConfig::from_file(&folder.join(deepbrdf_model::train::CONFIG_FILE))?;
    let log = saved_log(&checkpoint_path(folder))?;
    let name = folder.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    Ok(ScheduleRun { name, settings: config.schedule_summary(), log })
}
