//! `experiments highlights [--model DIR] [--collection C | --data DIR] [--limit N]`: where a
//! `slice` model's decodes lose the highlight: each material's dark hole and tinted centre at
//! every stage of its reconstruction (`deepbrdf_eval::deep::highlights`), as a markdown table;
//! `--profile MATERIAL`: one material's specular profile at every stage, beside the eq. (1)
//! reference.
use anyhow::Context;
use deepbrdf_data::Progress;
use deepbrdf_eval::deep::highlights::{stage_highlights, stage_profiles, stage_summary};
use deepbrdf_model::DeepBrdf;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: crate::args::model::ModelArg,
    #[command(flatten)]
    pub data: crate::args::data::DataArgs,
    /// Use only the first N materials (in name order).
    #[arg(long, value_name = "N")]
    pub limit: Option<usize>,
    #[command(flatten)]
    pub refine: crate::args::refine::RefineArg,
    /// Instead, print this material's specular profile (luminance over theta_d < 15 deg, by
    /// theta_h) beside the model's eq. (1) reference and each stage's.
    #[arg(long, value_name = "MATERIAL")]
    pub profile: Option<String>,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::args::device::device()?;
    let dir = args.model.dir()?;
    let model = DeepBrdf::load(&dir, &device)
        .with_context(|| format!("loading the model {}", dir.display()))?
        .with_refinement(args.refine.refinement()?);
    if let Some(material) = &args.profile {
        let (name, table) = deepbrdf_data::dataset::load_material(material, &args.data.cache())
            .with_context(|| format!("cannot read {material}"))?;
        println!("Specular profile of {name} (luminance, 1/sr):\n");
        println!("{}", stage_profiles(&model, &table)?);
        return Ok(());
    }
    let mut data = args.data.load_streamed(progress)?;
    if let Some(n) = args.limit {
        data.truncate(n);
    }
    progress.start(data.len() as u64, "materials");
    let mut rows = Vec::new();
    for (i, name) in data.names.iter().enumerate() {
        let table = data.tables().table(i)?;
        rows.extend(
            stage_highlights(&model, name, &table).with_context(|| format!("material {name}"))?,
        );
        progress.advance(1);
    }
    progress.finish();
    println!("{}", stage_summary(&rows));
    Ok(())
}
