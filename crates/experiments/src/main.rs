//! `experiments`: the DeepBRDF command line. Thin: parse, dispatch, print the error chain.
mod args;
mod broken_pipe;
mod cli;
mod commands;
mod editing;
mod latent_file;
mod progress;
mod progress_log;
mod readme_block;
mod recovery_inputs;
mod serve;
mod warnings;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = cli::Cli::parse();
    broken_pipe::install(&cli.command);
    warnings::install();
    match cli.run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {}", chain_message(&err));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes joined by ": ", leaving out a cause whose text the message already
/// ends with (the library errors print their source in their own message, e.g. "PATH: No space
/// left on device", so the plain chain would say it twice).
fn chain_message(err: &anyhow::Error) -> String {
    let mut message = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if message.ends_with(&text) {
            continue;
        }
        if !message.is_empty() {
            message.push_str(": ");
        }
        message.push_str(&text);
    }
    message
}
