//! `experiments encode MODEL FILE_OR_MATERIAL [-o latent.json]`: the k latent values of a BRDF
//! (eq. 2).
use crate::latent_file::LatentFile;
use anyhow::Context;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::Progress;
use deepbrdf_model::DeepBrdf;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// A trained model: its artifact directory or the training directory holding `model/`.
    pub model: PathBuf,
    /// A MERL .binary file or the name of a bundled material.
    pub material: String,
    /// Write the latent vector (with the model's id) to this JSON file.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub cache: crate::data_args::CacheArg,
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::device_arg::device()?;
    let model = DeepBrdf::load(&args.model, &device)?;
    let (name, table) = load_material(&args.material, &args.cache.cache())
        .with_context(|| format!("cannot read {}", args.material))?;
    let latent = model.encode(&table)?;
    let text: Vec<String> = latent.iter().map(|v| format!("{v:.6}")).collect();
    println!("{}", text.join(" "));
    if let Some(path) = &args.output {
        LatentFile::new(model.id(), &name, latent).save(path)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
