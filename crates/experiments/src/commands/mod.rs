//! One file per subcommand; `run` dispatches.
use crate::cli::{Cli, Command};
use crate::progress::Bars;

pub mod bench;
pub mod devices;
pub mod fetch_merl;

pub fn run(cli: Cli) -> anyhow::Result<()> {
    let progress = Bars::new(cli.quiet);
    match cli.command {
        Command::Devices(args) => devices::run(args, &progress),
        Command::Bench(args) => bench::run(args, &progress),
        Command::FetchMerl(args) => fetch_merl::run(args, cli.quiet),
    }
}
