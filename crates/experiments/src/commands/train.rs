//! `experiments train`: train DeepBRDF (§3.2) on a dataset and save the model artifact.
//!
//! `experiments train --k 10 [--preset slice|paper|cpu] [--epochs N] [--batch N] [--lr X] [--seed S]
//! [--slice-dropout P] --out DIR` starts a run; `--resume DIR` (or `--out DIR --resume`)
//! continues an interrupted one exactly where its last checkpoint left it, with the settings
//! saved in its checkpoint. The model is written to `DIR/model`; `DIR/train_log.csv` has one row
//! per epoch.
use crate::args::data::DataArgs;
use anyhow::{bail, Context};
use deepbrdf_data::bundled::Collection;
use deepbrdf_data::lock::FolderLock;
use deepbrdf_data::Progress;
use deepbrdf_model::autoencoder::train::saved_config;
use deepbrdf_model::autoencoder::{Architecture, ConvAlgorithm};
use deepbrdf_model::loss::LossNorm;
use deepbrdf_model::train::checkpoint_path;
use deepbrdf_model::{fit, DeepBrdf, Preset, SliceDropoutConfig, TrainConfig};
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Latent dimension k (§3.2 studies 5 to 40) [default: 10 with a preset, the file's with
    /// --config].
    #[arg(long)]
    pub k: Option<usize>,
    /// slice (the shipped model's network: one basis for all phi_d slices and a shared MLP
    /// decoder, sized for a 2-core CPU) or paper (Table 1, lr 2e-5, batch 32, 1000 epochs:
    /// for GPUs).
    #[arg(long, default_value = "slice", value_parser = parse_preset)]
    pub preset: Preset,
    /// A training configuration (JSON, as saved in DIR/train_config.json) instead of a preset.
    #[arg(long, value_name = "FILE", conflicts_with = "preset")]
    pub config: Option<PathBuf>,
    /// Epochs (default: the preset's).
    #[arg(long)]
    pub epochs: Option<usize>,
    /// BRDFs per batch (default: the preset's).
    #[arg(long)]
    pub batch: Option<usize>,
    /// Initial learning rate (default: the preset's).
    #[arg(long)]
    pub lr: Option<f64>,
    /// Seed of the initialisation, the shuffling and the augmentation [default: 0 with a preset,
    /// the file's with --config].
    #[arg(long)]
    pub seed: Option<u64>,
    /// Slice-dropout augmentation: the probability that an input loses phi_d slices (each
    /// missing one filled from its nearest kept one; the target stays whole).
    #[arg(long, value_name = "P")]
    pub slice_dropout: Option<f64>,
    /// Slice selections drawn from for slice dropout (every:N or random:K, comma-separated).
    #[arg(long, value_name = "LIST", value_delimiter = ',', default_value = "every:3,every:9")]
    pub slice_dropout_keep: Vec<String>,
    /// Passes over the held samples (the data's BRDFs and their augmentations) per epoch
    /// against one over a streamed --corpus, and their weight in the fit of the principal
    /// components (slice network) [default: 1].
    #[arg(long, value_name = "N")]
    pub held_passes: Option<usize>,
    /// The norm of eq. (4): l2 (the paper's) or l1 (Fig. 4's comparison) [default: the
    /// preset's or file's, l2].
    #[arg(long, value_name = "NORM", value_parser = parse_norm)]
    pub loss: Option<LossNorm>,
    /// How a convolutional network computes its convolutions: gemm (as matrix products) or
    /// direct (Burn's modules); the same parameters and values either way [default: the
    /// preset's or file's, gemm].
    #[arg(long, value_name = "ALGORITHM")]
    pub conv: Option<ConvAlgorithm>,
    /// Output directory (checkpoint, log, configuration, and the model in DIR/model).
    #[arg(long, value_name = "DIR", required_unless_present = "resume")]
    pub out: Option<PathBuf>,
    /// Stop at the end of the first epoch past this many seconds of training, writing the model
    /// of the epochs done so far (its provenance says how many) and keeping the checkpoint, so
    /// `--resume` continues the run (for a machine lent for a bounded time).
    #[arg(long, value_name = "SECONDS", value_parser = crate::args::time_limit::parse)]
    pub time_limit: Option<std::time::Duration>,
    /// Continue the interrupted run in DIR (or in --out), with its saved settings.
    #[arg(long, value_name = "DIR", num_args = 0..=1)]
    pub resume: Option<Option<PathBuf>>,
    #[command(flatten)]
    pub data: DataArgs,
    /// Train on these bundled collections too (comma-separated; their materials are named
    /// `COLLECTION/NAME`), e.g. `--add-collections nielsen2015,rgl,rgl-measured` for the
    /// shipped default model.
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub add_collections: Vec<Collection>,
    #[command(flatten)]
    pub corpus: crate::args::corpus::CorpusArg,
}

fn parse_preset(s: &str) -> Result<Preset, String> {
    s.parse()
}

fn parse_norm(s: &str) -> Result<LossNorm, String> {
    [LossNorm::L2, LossNorm::L1]
        .into_iter()
        .find(|n| n.name() == s.trim())
        .ok_or_else(|| format!("loss norm {s:?}: expected l2 or l1"))
}

impl Args {
    /// The configuration of a new run from the preset (or file) and the overrides.
    fn config(&self) -> anyhow::Result<TrainConfig> {
        let mut config = match &self.config {
            Some(path) => TrainConfig::from_file(path)?,
            None => self.preset.train_config(self.k.unwrap_or(10)),
        };
        if let Some(k) = self.k {
            config.model.latent = k;
        }
        if let Some(e) = self.epochs {
            config.epochs = e;
        }
        if let Some(b) = self.batch {
            config.batch_size = b;
        }
        if let Some(lr) = self.lr {
            config.learning_rate = lr;
        }
        if let Some(seed) = self.seed {
            config.seed = seed;
        }
        if let Some(p) = self.slice_dropout {
            config.slice_dropout = Some(
                SliceDropoutConfig::new()
                    .with_probability(p)
                    .with_selections(self.slice_dropout_keep.clone()),
            );
        }
        if let Some(norm) = self.loss {
            config.loss_norm = Some(norm);
        }
        if let Some(conv) = self.conv {
            config.model.set_conv(conv).context("--conv")?;
        }
        if let Some(passes) = self.held_passes {
            match &mut config.model.architecture {
                Architecture::Slice(layers) => layers.augmentation.held_passes = passes,
                Architecture::Convolutional(_) => {
                    bail!("--held-passes is a setting of the slice network, not of this one")
                }
            }
        }
        config.validate()?;
        Ok(config)
    }
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::args::device::device()?;
    let kind = crate::args::device::kind()?;
    // Held until the run ends: a second run on the same folder is refused.
    let (out, config, resume, lock) = run_folder(&args)?;
    let mut data = args.data.load(progress)?;
    if !args.add_collections.is_empty() {
        let more =
            crate::args::data::load_added(&args.add_collections, &args.data.cache(), progress)?;
        data.label = format!("{}+{}", data.label, more.label);
        data.names.extend(more.names);
        data.tables.extend(more.tables);
    }
    let streamed = args.corpus.streamed()?;
    eprintln!(
        "training DeepBRDF k = {} on {}{} ({} BRDFs), {} epochs of batches of {}, on {kind}",
        config.model.latent,
        data.label,
        streamed.as_ref().map_or_else(String::new, |s| format!("+{}", s.label())),
        data.len() + streamed.as_ref().map_or(0, |s| s.len()),
        config.epochs,
        config.batch_size
    );
    let tables: Vec<_> = data.tables.iter().collect();
    let model = fit(
        &config,
        &data.label,
        &data.names,
        &tables,
        streamed,
        &out,
        resume,
        args.time_limit,
        progress,
        &device,
    )?;
    print_trained(&model, &config, &out);
    drop(lock);
    Ok(())
}

/// The run's folder and configuration, whether it resumes, and the folder's lock: `--resume`
/// continues the run whose checkpoint is there with its saved configuration; otherwise `--out`
/// starts one with the configuration asked (read first: a bad `--config` file leaves no folder
/// behind), refused where a run already is.
fn run_folder(args: &Args) -> anyhow::Result<(PathBuf, TrainConfig, bool, FolderLock)> {
    match args.resume.clone().map(|d| d.or_else(|| args.out.clone())) {
        Some(None) => bail!("--resume needs a directory (--resume DIR or --out DIR --resume)"),
        Some(Some(dir)) => {
            if !checkpoint_path(&dir).is_file() {
                bail!("{}: no interrupted run to resume (no checkpoint.bin)", dir.display());
            }
            let lock = FolderLock::acquire(&dir)?;
            let config = saved_config(&dir)?;
            eprintln!(
                "resuming {} (k = {}, {} epochs, batch {}, lr {:e})",
                dir.display(),
                config.model.latent,
                config.epochs,
                config.batch_size,
                config.learning_rate
            );
            Ok((dir, config, true, lock))
        }
        None => {
            let out = args.out.clone().context("--out DIR is required")?;
            let config = args.config()?;
            let lock = FolderLock::acquire(&out)?;
            if checkpoint_path(&out).exists() {
                bail!(
                    "{} already holds a training run; continue it with --resume {} or choose \
                     another --out",
                    out.display(),
                    out.display()
                );
            }
            Ok((out, config, false, lock))
        }
    }
}

/// What the run trained, and how to continue it where the time limit stopped it.
fn print_trained(model: &DeepBrdf, config: &TrainConfig, out: &Path) {
    let p = model.provenance();
    println!(
        "trained {} epochs in {:.0} s: final loss {:.4e}, mapped-space MSE {:.4e} over {} BRDFs",
        p.epochs,
        p.train_seconds,
        p.final_loss,
        p.final_mse,
        p.materials.len()
    );
    if p.epochs < config.epochs {
        println!(
            "stopped at the time limit after {} of {} epochs; continue with --resume {}",
            p.epochs,
            config.epochs,
            out.display()
        );
    }
    println!("model {} written to {}", model.id(), out.join("model").display());
}
