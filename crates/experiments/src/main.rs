//! `experiments`: the DeepBRDF command line. Thin: parse, dispatch, print the error chain.
mod cli;
mod commands;
mod data_args;
mod device_arg;
mod latent_file;
mod progress;
mod scene_args;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = cli::Cli::parse();
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::FAILURE
        }
    }
}
