//! `experiments train-recovery [--model DIR] --set DIR --out DIR`: trains the recovery CNN of
//! Fig. 15 (§5.2) on a render set: each image's target is the model's encoding (eq. 2) of its
//! material; `--target attributes` trains the same CNN with 7 outputs on the Lambertian + GGX
//! attributes instead (the analytic baseline). Resumable (`--resume`); the network is saved to
//! `DIR/recovery` and names the model whose latent it predicts.
use crate::args::data::CacheArg;
use crate::args::model::ModelArg;
use crate::recovery_inputs::{load_tables, set_images};
use anyhow::bail;
use deepbrdf_data::lock::FolderLock;
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::recovery::{attribute_fits, latents};
use deepbrdf_model::recovery::artifact::RECOVERY_DIR;
use deepbrdf_model::recovery::{
    train_recovery, RecoveryArtifact, RecoveryData, RecoveryPreset, RecoveryProvenance,
    RecoveryTarget,
};
use deepbrdf_model::train::{LoopConfig, Session};
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::RenderSet;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArg,
    /// A render set written by `experiments render-set`.
    #[arg(long, value_name = "DIR")]
    pub set: PathBuf,
    /// Output folder: checkpoint, log, and the network in DIR/recovery.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// small (64x64 inputs, minutes on 2 cores; `cpu` is its earlier name) or paper (256x256,
    /// 300 epochs: for a GPU).
    #[arg(long, default_value = "small", value_parser = parse_preset)]
    pub preset: RecoveryPreset,
    /// What the CNN predicts: latent (the model's) or attributes (7 Lambertian + GGX values).
    #[arg(long, default_value = "latent", value_parser = ["latent", "attributes"])]
    pub target: String,
    /// Epochs (default: the preset's).
    #[arg(long)]
    pub epochs: Option<usize>,
    /// Seed of the initialisation, batches and mirroring.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Write a checkpoint at the end of an epoch once this many seconds have passed since the
    /// last (default: the preset's, 30 s for small); 0 checkpoints every epoch.
    #[arg(long, value_name = "S")]
    pub checkpoint_seconds: Option<f64>,
    /// Continue an interrupted run in --out.
    #[arg(long)]
    pub resume: bool,
    #[command(flatten)]
    pub cache: CacheArg,
}

fn parse_preset(s: &str) -> Result<RecoveryPreset, String> {
    s.parse()
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::args::device::device()?;
    let set = RenderSet::load(&args.set)?;
    let _lock = FolderLock::acquire(&args.out)?;
    let tables = load_tables(&set.header.materials, &args.cache.cache(), progress)?;
    let (target, targets) = targets(&args, &set, &tables, &device, progress)?;
    let config = args.preset.network(target.outputs());
    let settings = loop_settings(&args);
    let indices: Vec<usize> = (0..set.images.len()).collect();
    let images = set_images(&set, &args.set, &indices, config.input_side, progress)?;
    if let Some(note) = images.note(&args.set) {
        eprintln!("{note}");
    }
    let used = images.indices.len();
    let data = RecoveryData {
        side: config.input_side,
        outputs: config.outputs,
        targets: images
            .indices
            .iter()
            .flat_map(|&i| targets[&set.images[i].material].clone())
            .collect(),
        images: images.pixels,
    };
    let session = Session::new(&args.out, args.resume, progress, "recovery");
    let trained = train_recovery(&config, &settings, &data, &session, &device, progress)?;
    let Some(last) = trained.log.last() else { bail!("training ran no epoch") };
    let provenance = RecoveryProvenance {
        set: args.set.display().to_string(),
        set_digest: set.digest(),
        images: used,
        materials: set.header.materials.clone(),
        data_fingerprint: trained.fingerprint.clone(),
        train_config: serde_json::json!({"preset": args.preset.name(), "loop": settings}),
        epochs: trained.log.len(),
        final_loss: last.loss,
        train_seconds: trained.seconds,
        device: format!("{device:?}"),
    };
    let artifact = RecoveryArtifact::new(config, target, &trained, provenance)?;
    let dir = args.out.join(RECOVERY_DIR);
    artifact.save(&dir)?;
    let first = trained.log[0].loss;
    println!(
        "recovery CNN ({} preset, {} outputs) on {} images: L1 {:.4} -> {:.4} in {} epochs, \
         {:.0} s -> {} (id {})",
        args.preset,
        artifact.config().outputs,
        used,
        first,
        last.loss,
        trained.log.len(),
        trained.seconds,
        dir.display(),
        artifact.id()
    );
    Ok(())
}

/// What the network learns for each material of the set: the model's latent (a note where the
/// model has seen materials the set leaves out) or the fitted attributes.
fn targets(
    args: &Args,
    set: &RenderSet,
    tables: &std::collections::BTreeMap<String, MerlTable>,
    device: &deepbrdf_model::burn::tensor::Device,
    progress: &dyn Progress,
) -> anyhow::Result<(RecoveryTarget, std::collections::BTreeMap<String, Vec<f32>>)> {
    if args.target.as_str() != "latent" {
        return Ok((RecoveryTarget::Attributes, attribute_fits(tables, progress)?));
    }
    let model = DeepBrdf::load(&args.model.dir()?, device)?;
    let seen: Vec<&String> =
        set.header.excluded.iter().filter(|m| model.provenance().trained_on(m)).collect();
    if !seen.is_empty() {
        eprintln!(
            "note: the model was trained on {} of the materials this set leaves out \
             (e.g. {}): the autoencoder has seen them",
            seen.len(),
            seen[0]
        );
    }
    let target = RecoveryTarget::Latent { model_id: model.id().into(), k: model.k() };
    Ok((target, latents(&model, tables)?))
}

/// The training loop's settings: the preset's, with the seed, epochs and checkpoint interval
/// asked.
fn loop_settings(args: &Args) -> LoopConfig {
    let mut settings = args.preset.loop_config().with_seed(args.seed);
    if let Some(e) = args.epochs {
        settings = settings.with_epochs(e);
    }
    if let Some(c) = args.checkpoint_seconds {
        settings = settings.with_checkpoint_seconds(c);
    }
    settings
}
