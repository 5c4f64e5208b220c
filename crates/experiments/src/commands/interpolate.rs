//! `experiments interpolate [--model DIR] A B --steps 9 --out DIR`: blends two materials along
//! three paths (Fig. 10): the DeepBRDF latent `(1 - t) z_A + t z_B`, IPCA coefficients at the
//! same k, and a plain linear blend of the two tables as the reference; writes a strip of renders
//! (one row per path), the DeepBRDF tables (`--all-tables`: every path's) and `summary.md` with
//! each path's uniformity (coefficient of variation of the image RelAE between consecutive steps)
//! and plausibility.
use crate::args::data::DataArgs;
use crate::args::model::ModelArg;
use crate::editing::{blend, blend_tables, ModelCodec};
use anyhow::{bail, Context};
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::merl::write_merl;
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::baseline::{BaselineBasis, MappingKind};
use deepbrdf_eval::editing::{coefficient_of_variation, path_weights, plausibility};
use deepbrdf_eval::harness::Codec;
use deepbrdf_eval::metrics::{relae, ImageRelae, ImageRelaeConfig};
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::sheet::{contact_sheet, SheetConfig, Tile};
use deepbrdf_render::{Image, Tonemap};
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

/// One interpolation path: its name, tables and renders.
pub struct Path3 {
    pub name: String,
    pub tables: Vec<MerlTable>,
    pub images: Vec<Image>,
}

impl Path3 {
    /// RelAE between consecutive renders.
    pub fn steps(&self) -> anyhow::Result<Vec<f64>> {
        self.images.windows(2).map(|w| Ok(relae(&w[1], &w[0])?)).collect()
    }
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

/// Renders `tables` on the preview scene with `a`'s sampling (shared noise along a path).
pub fn render_all(reference: &ImageRelae, tables: &[MerlTable]) -> anyhow::Result<Vec<Image>> {
    tables.iter().map(|t| Ok(reference.render(t)?)).collect()
}

/// A strip: one row per path, captioned, each table rendered at the figure's settings with its
/// own importance sampling (the paths' `images`, at the measures' settings, are not reused), and
/// the renderer's noise there: the image RelAE between two seeds' renders of the first tile.
pub fn strip(
    paths: &[&Path3],
    captions: &dyn Fn(usize, usize) -> String,
    figure: &ImageRelaeConfig,
) -> anyhow::Result<(deepbrdf_render::image::Srgb8Image, f64)> {
    let tonemap = Tonemap { exposure: 1.0 };
    let mut tiles = Vec::new();
    let mut noise = None;
    for (row, p) in paths.iter().enumerate() {
        for (i, table) in p.tables.iter().enumerate() {
            let tile = ImageRelae::new(table, figure)?;
            if noise.is_none() {
                noise = Some(tile.noise(table)?);
            }
            let image = tile.reference().to_srgb8(&tonemap, [24, 24, 24]);
            tiles.push(Tile { image, caption: captions(row, i) });
        }
    }
    let noise = noise.context("a strip of no tables")?;
    let columns = paths.first().map(|p| p.tables.len()).unwrap_or(1) as u32;
    let config = SheetConfig { columns, ..SheetConfig::default() };
    Ok((contact_sheet(&tiles, &config)?, noise))
}

/// How a figure's tiles were rendered, and their noise, for its caption.
pub fn figure_caption(figure: &ImageRelaeConfig, noise: f64) -> String {
    let r = &figure.render;
    format!(
        "{} px tiles, {} Sobol samples per pixel, seed {}; render noise (image RelAE between two seeds' renders of the first tile) {noise:.4}.",
        r.size, r.spp, r.seed
    )
}

/// The three paths from `a` to `b` (`ipca` optional).
pub fn paths(
    model: &DeepBrdf,
    ipca: Option<&dyn Codec>,
    a: &MerlTable,
    b: &MerlTable,
    steps: usize,
    progress: &dyn Progress,
) -> anyhow::Result<Vec<Path3>> {
    let reference = ImageRelae::new(a, &ImageRelaeConfig::default())?;
    let ts = path_weights(steps);
    let deep = ModelCodec(model);
    let mut codecs: Vec<&dyn Codec> = vec![&deep];
    codecs.extend(ipca);
    let mut out = Vec::new();
    progress.start((steps * (codecs.len() + 1)) as u64, "interpolating");
    for (codec, name) in codecs.iter().zip(["DeepBRDF", "IPCA"]) {
        let (za, zb) = (codec.encode(a)?, codec.encode(b)?);
        let mut tables = Vec::new();
        for &t in &ts {
            tables.push(codec.decode(&blend(&za, &zb, t))?);
            progress.advance(1);
        }
        let images = render_all(&reference, &tables)?;
        out.push(Path3 { name: name.into(), tables, images });
    }
    let mut tables = Vec::new();
    for &t in &ts {
        tables.push(blend_tables(a, b, t)?);
        progress.advance(1);
    }
    let images = render_all(&reference, &tables)?;
    out.push(Path3 { name: "linear blend".into(), tables, images });
    progress.finish();
    Ok(out)
}

/// A markdown table of the paths' uniformity and plausibility.
pub fn summary(paths: &[Path3]) -> anyhow::Result<String> {
    let mut s = String::from(
        "| path | CV of consecutive image RelAE | mean step RelAE | negative values | max directional albedo |\n| --- | ---: | ---: | ---: | ---: |\n",
    );
    for p in paths {
        let steps = p.steps()?;
        let mean = steps.iter().sum::<f64>() / steps.len() as f64;
        let checks: Vec<_> = p.tables.iter().map(plausibility).collect();
        let negative: usize = checks.iter().map(|c| c.negative_values).sum();
        let albedo = checks.iter().map(|c| c.max_albedo).fold(f64::NEG_INFINITY, f64::max);
        s += &format!(
            "| {} | {:.3} | {:.4} | {negative} | {albedo:.3} |\n",
            p.name,
            coefficient_of_variation(&steps),
            mean
        );
    }
    Ok(s)
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
    let refs: Vec<&Path3> = paths.iter().collect();
    let figure = args.figure.config()?;
    let (sheet, noise) = strip(
        &refs,
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
