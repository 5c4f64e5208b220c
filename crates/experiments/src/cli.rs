//! Command-line definition. Each subcommand's arguments live in its own file under `commands/`.
use crate::commands;
use crate::progress::Bars;
use clap::{Parser, Subcommand};

/// DeepBRDF: a deep, compact and editable representation of measured BRDFs (Hu et al., CGF 2020).
#[derive(Debug, Parser)]
#[command(name = "experiments", version, about)]
pub struct Cli {
    /// Show no progress bars.
    #[arg(long, short, global = true)]
    pub quiet: bool,
    /// Compute backend for the networks: flex (default), ndarray, wgpu or cuda, as compiled in.
    #[arg(long, global = true, value_name = "NAME", value_parser = parse_device)]
    pub device: Option<deepbrdf_model::DeviceKind>,
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// List the compute devices compiled into this binary.
    Devices(commands::devices::Args),
    /// Benchmarks that print speed numbers.
    Bench(commands::bench::Args),
    /// Download the official MERL BRDF database (100 `.binary` files), verified by SHA-256.
    FetchMerl(commands::fetch_merl::Args),
    /// Describe a MERL table: a .binary file or a bundled material (header, valid cells,
    /// per-channel statistics, albedo at normal incidence).
    Info(commands::info::Args),
    /// The materials each fold of the k-fold split scores (`--fold F`: one fold, a name a line).
    Folds(commands::folds::Args),
    /// Write MERL .binary files tabulated from the bundled NBRDF networks.
    Tabulate(commands::tabulate::Args),
    /// Write a corpus of analytic materials with known parameters: the parameter
    /// file and, with --tables K, the first K materials as MERL .binary files.
    Corpus(commands::corpus::Args),
    /// Pack folders of JSON NBRDF networks into the bundled .nbrdf files.
    PackNbrdf(commands::pack_nbrdf::Args),
    /// Rewrite models, recovery networks and .svg charts (or folders of them) in place in their
    /// compact, lossless forms (maintainers: the repository's size).
    Compact(commands::compact::Args),
    /// Train DeepBRDF (§3.2) on a dataset; resumable.
    Train(commands::train::Args),
    /// Print the k latent values of a BRDF under a trained model (eq. 2).
    Encode(commands::encode::Args),
    /// Decode a latent vector into a MERL .binary file (eq. 3).
    Decode(commands::decode::Args),
    /// Encode and decode a BRDF, optionally from 1/3 or 1/9 of its slices (Fig. 2).
    Reconstruct(commands::reconstruct::Args),
    /// Where a `slice` model's decodes lose the highlight: dark holes and tinted centres at
    /// each stage of the reconstruction (basis, linear path, encoder, refined encoding).
    Highlights(commands::highlights::Args),
    /// The main job: DeepBRDF, PCA and IPCA at each k (Figs. 2, 3 and 7), tables and plots.
    SweepK(commands::sweep_k::Args),
    /// Render a material (a MERL .binary file or a bundled material) to PNG and EXR.
    Render(commands::render::Args),
    /// Render two materials under the same settings; print RelAE, RMSE and PSNR and write a
    /// false-colour difference image.
    Compare(commands::compare::Args),
    /// Render every material of a dataset on spheres, in one captioned contact sheet.
    Sheet(commands::sheet::Args),
    /// Convert a real RGL measurement (.bsdf tensor file) to a MERL .binary file.
    Convert(commands::convert::Args),
    /// Write a material as an RGL .bsdf file (isotropic RGB tensor file, Dupuy & Jakob 2018),
    /// which Mitsuba 3 and pbrt-v4 render with their `measured` material.
    ExportBsdf(commands::export_bsdf::Args),
    /// Round trip of real RGL measurements (measurement -> MERL -> .bsdf): image RelAE of the
    /// exports against the measurement, beside the MERL table's own.
    RoundTrip(commands::round_trip::Args),
    /// Evaluate the PCA and IPCA baselines (§4): summary table, CSV, plots.
    Baselines(commands::baselines::Args),
    /// Render the synthetic training set of single-image recovery (§5.2): one material per
    /// image on random shapes, views and skies; resumable.
    RenderSet(commands::render_set::Args),
    /// Train the recovery CNN (Fig. 15) from images to a model's latent (or to the 7
    /// attributes); resumable.
    TrainRecovery(commands::train_recovery::Args),
    /// Recover a MERL BRDF from one photo of an object (§5.2).
    ///
    /// Assumptions: one object of one homogeneous, isotropic material, roughly centred and
    /// wholly in view, lit by a sun-and-sky-like outdoor light, in front of a plain dark
    /// background (or cut out by an alpha channel); PNG, JPEG or EXR of any size (the object is
    /// cropped and resized to the network's input). Blank, saturated or object-less photos are
    /// refused with the reason.
    Recover(commands::recover::Args),
    /// Measure single-image recovery against its baselines on held-out and other materials;
    /// the table, Fig. 16 and Fig. 17 under results/recovery.
    FiguresRecovery(commands::figures_recovery::Args),
    /// Estimate the 7 editable attributes (§5.1: diffuse and specular albedo RGB, GGX
    /// roughness) of materials by a Lambertian + GGX fit; CSV and table.
    Attributes(commands::attributes::Args),
    /// Train the attribute-to-latent regressor of §5.1 (eq. 7) for a DeepBRDF model (and, with
    /// --ipca, for IPCA coefficients at the same k).
    TrainRegressor(commands::train_regressor::Args),
    /// Edit a material's diffuse albedo, specular albedo or roughness (§5.1) through a model's
    /// regressor and decoder.
    Edit(commands::edit::Args),
    /// Blend two materials in the DeepBRDF latent space, in IPCA coefficients and linearly
    /// (Fig. 10): renders and tables.
    Interpolate(commands::interpolate::Args),
    /// Fig. 9: materials no representation was fitted to (default: the real RGL measurements),
    /// as measured, as DeepBRDF and as IPCA reconstruct them, with the image RelAE of each;
    /// Fig. 8 with `--baseline sun2018` (Sun et al. 2018's separation instead of IPCA).
    FiguresGeneralize(commands::figures_generalize::Args),
    /// Fig. 4: the same network trained with the L2 and the L1 loss (`train --loss l1`), each
    /// material as measured and as each model reconstructs it, with the image RelAE of each.
    FiguresLoss(commands::figures_loss::Args),
    /// Table 1's training schedules compared: the loss curves of runs against epochs and
    /// training time (`scripts/table1-schedules.sh`), with a summary table.
    FiguresSchedules(commands::figures_schedules::Args),
    /// Figs. 5 and 6: the materials' latents in their principal plane, and a few materials
    /// reconstructed by DeepBRDF, PCA and IPCA at several k, with the image RelAE of each.
    FiguresQuality(commands::figures_quality::Args),
    /// The editing figures (Figs. 10, 12, 13, 14) and the measured edit suite.
    FiguresEditing(commands::figures_editing::Args),
    /// Edits against known answers: analytic corpus materials edited by the analytic edit,
    /// DeepBRDF and IPCA, each scored by its distance to the material with the parameter changed.
    EditKnown(commands::edit_known::Args),
    /// The browser material editor: sliders for the 7 attributes and a blend, a live preview,
    /// downloads of the edited .binary and latent (http://127.0.0.1:7878/ by default).
    Serve(commands::serve::Args),
}

fn parse_device(s: &str) -> Result<deepbrdf_model::DeviceKind, String> {
    s.parse()
}

impl Cli {
    /// Runs the parsed command.
    pub fn run(self) -> anyhow::Result<()> {
        let cli = self;
        let progress = Bars::new(cli.quiet);
        crate::args::device::select(cli.device);
        match cli.command {
            Command::Devices(args) => commands::devices::run(args, &progress),
            Command::Bench(args) => commands::bench::run(args, &progress),
            Command::FetchMerl(args) => commands::fetch_merl::run(args, cli.quiet),
            Command::Info(args) => commands::info::run(args, &progress),
            Command::Folds(args) => commands::folds::run(args, &progress),
            Command::Tabulate(args) => commands::tabulate::run(args, &progress),
            Command::PackNbrdf(args) => commands::pack_nbrdf::run(args, &progress),
            Command::Compact(args) => commands::compact::run(args, &progress),
            Command::Corpus(args) => commands::corpus::run(args, &progress),
            Command::Train(args) => commands::train::run(args, &progress),
            Command::Encode(args) => commands::encode::run(args, &progress),
            Command::Decode(args) => commands::decode::run(args, &progress),
            Command::Reconstruct(args) => commands::reconstruct::run(args, &progress),
            Command::Highlights(args) => commands::highlights::run(args, &progress),
            Command::SweepK(args) => commands::sweep_k::run(args, cli.quiet, &progress),
            Command::Render(args) => commands::render::run(args, &progress),
            Command::Compare(args) => commands::compare::run(args, &progress),
            Command::Convert(args) => commands::convert::run(args, &progress),
            Command::ExportBsdf(args) => commands::export_bsdf::run(args, &progress),
            Command::RoundTrip(args) => commands::round_trip::run(args, &progress),
            Command::Sheet(args) => commands::sheet::run(args, &progress),
            Command::Serve(args) => commands::serve::run(args, &progress),
            Command::Baselines(args) => commands::baselines::run(args, &progress),
            Command::Attributes(args) => commands::attributes::run(args, &progress),
            Command::TrainRegressor(args) => commands::train_regressor::run(args, &progress),
            Command::Edit(args) => commands::edit::run(args, &progress),
            Command::Interpolate(args) => commands::interpolate::run(args, &progress),
            Command::FiguresEditing(args) => commands::figures_editing::run(args, &progress),
            Command::EditKnown(args) => commands::edit_known::run(args, &progress),
            Command::FiguresGeneralize(args) => commands::figures_generalize::run(args, &progress),
            Command::FiguresLoss(args) => commands::figures_loss::run(args, &progress),
            Command::FiguresSchedules(args) => commands::figures_schedules::run(args, &progress),
            Command::FiguresQuality(args) => commands::figures_quality::run(args, &progress),
            Command::RenderSet(args) => commands::render_set::run(args, &progress),
            Command::TrainRecovery(args) => commands::train_recovery::run(args, &progress),
            Command::Recover(args) => commands::recover::run(args, &progress),
            Command::FiguresRecovery(args) => commands::figures_recovery::run(args, &progress),
        }
    }
}
