//! `experiments`: the DeepBRDF command line. Thin: parse, dispatch, print the error chain.
mod cli;
mod commands;
mod data_args;
mod deep_method;
mod device_arg;
mod latent_file;
mod mapped_input;
mod measured_brdf;
mod nested_baseline;
mod progress;
mod progress_log;
mod readme_block;
mod robustness;
mod scene_args;
mod slices_figure;

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
