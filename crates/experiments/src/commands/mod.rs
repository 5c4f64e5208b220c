//! One file per subcommand; `run` dispatches.
use crate::cli::{Cli, Command};
use crate::progress::Bars;

pub mod attributes;
pub mod baselines;
pub mod bench;
pub mod compact;
pub mod compare;
pub mod convert;
pub mod corpus;
pub mod decode;
pub mod devices;
pub mod edit;
pub mod edit_known;
pub mod encode;
pub mod export_bsdf;
pub mod fetch_merl;
pub mod figures_editing;
pub mod figures_generalize;
pub mod figures_loss;
pub mod figures_quality;
pub mod figures_recovery;
pub mod folds;
pub mod highlights;
pub mod info;
pub mod interpolate;
pub mod pack_nbrdf;
pub mod reconstruct;
pub mod recover;
pub mod render;
pub mod render_set;
pub mod round_trip;
pub mod serve;
pub mod sheet;
pub mod sweep_k;
pub mod tabulate;
pub mod train;
pub mod train_recovery;
pub mod train_regressor;

pub fn run(cli: Cli) -> anyhow::Result<()> {
    let progress = Bars::new(cli.quiet);
    crate::args::device::select(cli.device);
    match cli.command {
        Command::Devices(args) => devices::run(args, &progress),
        Command::Bench(args) => bench::run(args, &progress),
        Command::FetchMerl(args) => fetch_merl::run(args, cli.quiet),
        Command::Info(args) => info::run(args, &progress),
        Command::Folds(args) => folds::run(args, &progress),
        Command::Tabulate(args) => tabulate::run(args, &progress),
        Command::PackNbrdf(args) => pack_nbrdf::run(args, &progress),
        Command::Compact(args) => compact::run(args, &progress),
        Command::Corpus(args) => corpus::run(args, &progress),
        Command::Train(args) => train::run(args, &progress),
        Command::Encode(args) => encode::run(args, &progress),
        Command::Decode(args) => decode::run(args, &progress),
        Command::Reconstruct(args) => reconstruct::run(args, &progress),
        Command::Highlights(args) => highlights::run(args, &progress),
        Command::SweepK(args) => sweep_k::run(args, cli.quiet, &progress),
        Command::Render(args) => render::run(args, &progress),
        Command::Compare(args) => compare::run(args, &progress),
        Command::Convert(args) => convert::run(args, &progress),
        Command::ExportBsdf(args) => export_bsdf::run(args, &progress),
        Command::RoundTrip(args) => round_trip::run(args, &progress),
        Command::Sheet(args) => sheet::run(args, &progress),
        Command::Serve(args) => serve::run(args, &progress),
        Command::Baselines(args) => baselines::run(args, &progress),
        Command::Attributes(args) => attributes::run(args, &progress),
        Command::TrainRegressor(args) => train_regressor::run(args, &progress),
        Command::Edit(args) => edit::run(args, &progress),
        Command::Interpolate(args) => interpolate::run(args, &progress),
        Command::FiguresEditing(args) => figures_editing::run(args, &progress),
        Command::EditKnown(args) => edit_known::run(args, &progress),
        Command::FiguresGeneralize(args) => figures_generalize::run(args, &progress),
        Command::FiguresLoss(args) => figures_loss::run(args, &progress),
        Command::FiguresQuality(args) => figures_quality::run(args, &progress),
        Command::RenderSet(args) => render_set::run(args, &progress),
        Command::TrainRecovery(args) => train_recovery::run(args, &progress),
        Command::Recover(args) => recover::run(args, &progress),
        Command::FiguresRecovery(args) => figures_recovery::run(args, &progress),
    }
}
