//! `experiments bench ...`: benchmarks that print speed numbers (the project's speed targets are
//! checked by these commands, not by timed tests).
use deepbrdf_data::Progress;

pub mod tabulate;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub what: What,
}

/// What to benchmark.
#[derive(Debug, clap::Subcommand)]
pub enum What {
    /// Tabulating bundled NBRDF networks onto the MERL grid (target: 100 materials < 30 s).
    Tabulate(tabulate::Args),
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    match args.what {
        What::Tabulate(a) => tabulate::run(a, progress),
    }
}
