//! Command-line definition. Each subcommand's arguments live in its own file under `commands/`.
use crate::commands;
use clap::{Parser, Subcommand};

/// DeepBRDF: a deep, compact and editable representation of measured BRDFs (Hu et al., CGF 2020).
#[derive(Debug, Parser)]
#[command(name = "experiments", version, about)]
pub struct Cli {
    /// Show no progress bars.
    #[arg(long, short, global = true)]
    pub quiet: bool,
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// List the compute devices compiled into this binary.
    Devices(commands::devices::Args),
    /// Benchmarks that print speed numbers.
    Bench(commands::bench::Args),
    /// Describe a MERL table: a .binary file or a bundled material (header, valid cells,
    /// per-channel statistics, albedo at normal incidence).
    Info(commands::info::Args),
    /// Write MERL .binary files tabulated from the bundled NBRDF networks.
    Tabulate(commands::tabulate::Args),
    /// Pack folders of JSON NBRDF networks into the bundled .nbrdf files.
    PackNbrdf(commands::pack_nbrdf::Args),
    /// Evaluate the PCA and IPCA baselines (§4): summary table, CSV, plots.
    Baselines(commands::baselines::Args),
}
