//! `experiments decode MODEL latent.json -o out.binary`: the full MERL table of a latent vector
//! (eq. 3), written as a MERL .binary file any renderer reads.
use crate::latent_file::LatentFile;
use anyhow::bail;
use deepbrdf_data::merl::write_merl;
use deepbrdf_data::Progress;
use deepbrdf_model::DeepBrdf;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// A trained model: its artifact directory or the training directory holding `model/`.
    pub model: PathBuf,
    /// A latent vector written by `experiments encode -o`.
    pub latent: PathBuf,
    /// The MERL .binary file to write.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Decode even if the latent vector was made by another model.
    #[arg(long)]
    pub force: bool,
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::device_arg::device()?;
    let model = DeepBrdf::load(&args.model, &device)?;
    let latent = LatentFile::load(&args.latent)?;
    if latent.model_id != model.id() && !args.force {
        bail!(
            "{}: this latent vector was made by model {}, not by {} (model {}); pass --force to \
             decode it anyway",
            args.latent.display(),
            latent.model_id,
            args.model.display(),
            model.id()
        );
    }
    let table = model.decode(&latent.latent)?;
    write_merl(&table, &args.output)?;
    eprintln!("wrote {} ({} valid cells)", args.output.display(), table.valid_cells());
    Ok(())
}
