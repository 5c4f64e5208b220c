//! `experiments folds`: which materials each fold of the harness scores (the split every
//! k-fold command uses, deterministic in the seed), so a held-out experiment on one fold can
//! be set up by hand: `experiments folds --fold 0` lists fold 0's materials, one a line.
use crate::args::data::DataArgs;
use anyhow::bail;
use deepbrdf_data::Progress;
use deepbrdf_eval::harness::Mode;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The split: kfold:N (in-sample and generalize have one fold holding every material).
    #[arg(long, default_value = "kfold:5")]
    pub mode: Mode,
    /// Seed of the split (the harness' `--seed`).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Print only the materials this fold scores, one a line (else `fold<TAB>material` for
    /// every material, in fold order).
    #[arg(long, value_name = "F")]
    pub fold: Option<usize>,
    #[command(flatten)]
    pub data: DataArgs,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    if args.mode == Mode::Generalize {
        bail!("generalize mode scores other collections: it has no split of these materials");
    }
    let data = args.data.load_streamed(progress)?;
    let folds = args.mode.folds(data.names.len(), 0, args.seed)?;
    if let Some(f) = args.fold {
        if f >= folds.len() {
            bail!("--fold {f}: {} mode has folds 0 to {}", args.mode, folds.len() - 1);
        }
    }
    for fold in folds.iter().filter(|fold| args.fold.is_none_or(|f| f == fold.index)) {
        for &i in &fold.test {
            match args.fold {
                Some(_) => println!("{}", data.names[i]),
                None => println!("{}\t{}", fold.index, data.names[i]),
            }
        }
    }
    Ok(())
}
