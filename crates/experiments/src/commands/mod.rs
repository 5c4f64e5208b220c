//! One file per subcommand; `run` dispatches.
use crate::cli::{Cli, Command};
use crate::progress::Bars;

pub mod baselines;
pub mod bench;
pub mod devices;
pub mod info;
pub mod pack_nbrdf;
pub mod tabulate;

pub fn run(cli: Cli) -> anyhow::Result<()> {
    let progress = Bars::new(cli.quiet);
    match cli.command {
        Command::Devices(args) => devices::run(args, &progress),
        Command::Bench(args) => bench::run(args, &progress),
        Command::Info(args) => info::run(args, &progress),
        Command::Tabulate(args) => tabulate::run(args, &progress),
        Command::PackNbrdf(args) => pack_nbrdf::run(args, &progress),
        Command::Baselines(args) => baselines::run(args, &progress),
    }
}
