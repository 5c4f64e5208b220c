//! `experiments decode [--model DIR] latent.json -o out.binary`: the full MERL table of a latent vector
//! (eq. 3), written as a MERL .binary file any renderer reads.
use crate::latent_file::LatentFile;
use anyhow::bail;
use deepbrdf_data::merl::write_merl;
use deepbrdf_data::Progress;
use deepbrdf_model::DeepBrdf;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// [MODEL] LATENT: a latent vector written by `experiments encode -o`; before it, optionally, a trained
    /// model (the earlier form of `--model DIR`).
    #[arg(value_name = "[MODEL] LATENT", num_args = 1..=2, required = true)]
    pub inputs: Vec<String>,
    #[command(flatten)]
    pub model: crate::args::model::ModelArg,
    /// The MERL .binary file to write.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Decode even if the latent vector was made by another model.
    #[arg(long)]
    pub force: bool,
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::args::device::device()?;
    let (model_dir, input) = args.model.with_positional(&args.inputs)?;
    let model = DeepBrdf::load(&model_dir, &device)?;
    let latent = LatentFile::load(std::path::Path::new(&input))?;
    if latent.model_id != model.id() && !args.force {
        bail!(
            "{}: this latent vector was made by model {}, not by {} (model {}); pass --force to \
             decode it anyway",
            input,
            latent.model_id,
            model_dir.display(),
            model.id()
        );
    }
    let table = model.decode(&latent.latent)?;
    write_merl(&table, &args.output)?;
    eprintln!("wrote {} ({} valid cells)", args.output.display(), table.valid_cells());
    Ok(())
}
