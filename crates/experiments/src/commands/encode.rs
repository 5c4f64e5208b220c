//! `experiments encode [--model DIR] FILE_OR_MATERIAL [-o latent.json]`: the k latent values of a BRDF
//! (eq. 2).
use crate::latent_file::LatentFile;
use anyhow::Context;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::Progress;
use deepbrdf_model::DeepBrdf;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub input: crate::args::model::ModelMaterialArg,
    /// Write the latent vector (with the model's id) to this JSON file.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub refine: crate::args::refine::RefineArg,
    #[command(flatten)]
    pub cache: crate::args::data::CacheArg,
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::args::device::device()?;
    let (model_dir, input) = args.input.resolve()?;
    let model = DeepBrdf::load(&model_dir, &device)?.with_refinement(args.refine.refinement()?);
    let (name, table) = load_material(&input, &args.cache.cache())
        .with_context(|| format!("cannot read {input}"))?;
    let latent = model.encode(&table)?;
    let text: Vec<String> = latent.iter().map(|v| format!("{v:.6}")).collect();
    println!("{}", text.join(" "));
    if let Some(path) = &args.output {
        LatentFile::new(model.id(), &name, latent).save(path)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
