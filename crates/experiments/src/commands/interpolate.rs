//! `experiments interpolate [--model DIR] A B --steps 9 --out DIR`: blends two materials along
//! three paths (Fig. 10): the DeepBRDF latent `(1 - t) z_A + t z_B`, IPCA coefficients at the
//! same k, and a plain linear blend of the two tables as the reference; writes a strip of renders
//! (one row per path), the DeepBRDF tables (`--all-tables`: every path's) and `summary.md` with
//! each path's uniformity (coefficient of variation of the image RelAE between consecutive steps)
//! and plausibility.
use crate::args::data::DataArgs;
use crate::args::model::ModelArg;
use anyhow::{bail, Context};
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::merl::write_merl;
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::baseline::{BaselineBasis, MappingKind};
use deepbrdf_eval::editing::interpolation::{paths, summary};
use deepbrdf_eval::figures::{figure_caption, strip};
use deepbrdf_model::DeepBrdf;
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArg,
    /// The first material (a MERL .binary file or a bundled material).
    pub a: String,
    /// The second material.
    pub b: String,
    /// Steps along each path, both ends included.
    #[arg(long, default_value_t = 9, value_parser = clap::value_parser!(u32).range(2..=33))]
    pub steps: u32,
    /// Output folder.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// An IPCA basis file [default: <model>/regressor/ipca.basis when present, else IPCA fitted
    /// at the model's k on --collection / --data].
    #[arg(long, value_name = "FILE")]
    pub ipca_basis: Option<PathBuf>,
    /// The strip's renders.
    #[command(flatten)]
    pub figure: crate::args::figure::FigureArg,
    /// Write every path's tables, not only DeepBRDF's (35 MB each).
    #[arg(long)]
    pub all_tables: bool,
    #[command(flatten)]
    pub data: DataArgs,
}

/// The IPCA basis for `model_dir`: `given`, else the regressor folder's, else fitted on `data`.
pub fn ipca_basis(
    model_dir: &Path,
    given: Option<&Path>,
    k: usize,
    data: &DataArgs,
    progress: &dyn Progress,
) -> anyhow::Result<Arc<BaselineBasis>> {
    let shipped =
        model_dir.join(crate::editing::REGRESSOR_DIR).join(crate::editing::IPCA_BASIS_FILE);
    let path = given.map(Path::to_path_buf).or_else(|| shipped.exists().then_some(shipped));
    Ok(Arc::new(match path {
        Some(p) => BaselineBasis::load(&p).with_context(|| format!("loading {}", p.display()))?,
        None => {
            let set = data.load(progress)?;
            let refs: Vec<_> = set.tables.iter().collect();
            BaselineBasis::fit("IPCA", MappingKind::LogRelative, &refs, k, progress)?
        }
    }))
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let model_dir = args.model.dir()?;
    if args.out.exists() && std::fs::read_dir(&args.out)?.next().is_some() {
        if !args.out.join("summary.md").exists() {
            bail!(
                "{} exists and is not an interpolate output; not writing into it",
                args.out.display()
            );
        }
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let cache = args.data.cache();
    let (name_a, a) =
        load_material(&args.a, &cache).with_context(|| format!("loading '{}'", args.a))?;
    let (name_b, b) =
        load_material(&args.b, &cache).with_context(|| format!("loading '{}'", args.b))?;
    let device = crate::args::device::device()?;
    let model = DeepBrdf::load(&model_dir, &device)
        .with_context(|| format!("loading the model {}", model_dir.display()))?;
    let basis =
        ipca_basis(&model_dir, args.ipca_basis.as_deref(), model.k(), &args.data, progress)?;
    let ipca = basis.codec(model.k())?;
    let steps = args.steps as usize;
    let paths = paths(&model, Some(&ipca), &a, &b, steps, progress)?;
    for p in &paths {
        if p.name != "DeepBRDF" && !args.all_tables {
            continue;
        }
        let stem: String = p
            .name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' })
            .collect();
        for (i, t) in p.tables.iter().enumerate() {
            write_merl(t, args.out.join(format!("{stem}-{i:02}.binary")))?;
        }
    }
    let rows: Vec<&[MerlTable]> = paths.iter().map(|p| p.tables.as_slice()).collect();
    let figure = args.figure.config()?;
    let (sheet, noise) = strip(
        &rows,
        &|row, i| format!("{} t={:.2}", paths[row].name, i as f64 / (steps - 1) as f64),
        &figure,
    )?;
    let png = args.out.join("strip.png");
    sheet.write_png(&png)?;
    let text = format!(
        "# {name_a} -> {name_b}, {steps} steps (model {}, k = {})\n\nWritten by `experiments interpolate`; image RelAE between consecutive renders (128 px sphere, sun and sky, 16 spp, the first material's sampling). The strip: {}\n\n{}",
        model.id(),
        model.k(),
        figure_caption(&figure, noise),
        summary(&paths)?
    );
    deepbrdf_data::files::write_atomic(&args.out.join("summary.md"), text.as_bytes())?;
    println!("{text}\nwrote {} and the tables in {}", png.display(), args.out.display());
    Ok(())
}
