//! `experiments figures-generalize [--model DIR] [--collection rgl-measured | --data DIR]`:
//! Fig. 9 of Hu et al. (2020) on materials no representation was fitted to (by default the
//! seven real RGL measurements): each material rendered as measured, as DeepBRDF reconstructs it
//! (eq. 2 then eq. 3) and as IPCA does at the model's k, IPCA fitted on the model's training
//! data; the image RelAE of each reconstruction under its caption (the harness's measure,
//! [`ImageRelae`]: the preview sphere, sun and sky), rendered at the figure settings
//! (`--size`, `--spp`, `--seed`), with the renderer's noise measured beside it.
use crate::args::data::{load_added, CacheArg};
use crate::args::model::ModelArg;
use crate::editing::ModelCodec;
use anyhow::{bail, Context};
use deepbrdf_data::bundled::Collection;
use deepbrdf_data::dataset::{DataSource, Dataset};
use deepbrdf_data::files::write_atomic;
use deepbrdf_data::Progress;
use deepbrdf_eval::baseline::{BaselineBasis, MappingKind};
use deepbrdf_eval::harness::Codec;
use deepbrdf_eval::metrics::{relae, ImageRelae};
use deepbrdf_eval::stats::finite_mean;
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::sheet::{contact_sheet, SheetConfig, Tile};
use deepbrdf_render::Tonemap;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArg,
    /// The materials to show: a bundled collection (default: the real RGL measurements).
    #[arg(long, value_name = "NAME", default_value = "rgl-measured", conflicts_with = "data")]
    pub collection: Collection,
    /// A folder of MERL .binary files to show instead.
    #[arg(long, value_name = "DIR")]
    pub data: Option<PathBuf>,
    /// Fit IPCA on this folder of MERL .binary files [default: the bundled `merl` collection,
    /// which must be what the model was trained on].
    #[arg(long, value_name = "DIR")]
    pub ipca_data: Option<PathBuf>,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "results/fig9")]
    pub out: PathBuf,
    #[command(flatten)]
    pub figure: crate::args::figure::FigureArg,
    #[command(flatten)]
    pub cache: CacheArg,
}

/// IPCA's training data when the model's: the bundled collections of its provenance label
/// (`merl`, or `merl+nielsen2015+...` as `train --add-collections` writes it), loaded as
/// `train` loaded them (the first as it is, the added ones by [`load_added`]).
fn model_collections(
    label: &str,
    cache: &deepbrdf_data::cache::Cache,
    progress: &dyn Progress,
) -> anyhow::Result<Dataset> {
    let parsed: Result<Vec<Collection>, _> = label.split('+').map(str::parse).collect();
    let Ok(collections) = parsed else {
        bail!(
            "the model was trained on '{label}', not bundled collections: give --ipca-data DIR \
             with its training materials, so that IPCA is fitted on the same data"
        );
    };
    let source = DataSource::Bundled(collections[0]);
    let mut train = Dataset::load(&source, cache, progress)
        .with_context(|| format!("loading IPCA's training data {}", source.label()))?;
    let added = load_added(&collections[1..], cache, progress)?;
    train.names.extend(added.names);
    train.tables.extend(added.tables);
    train.label = label.to_string();
    Ok(train)
}

/// One material's row.
struct Row {
    material: String,
    noise: f64,
    deepbrdf: f64,
    ipca: f64,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let config = args.figure.config()?;
    let device = crate::args::device::device()?;
    let model = DeepBrdf::load(&args.model.dir()?, &device)?;
    let k = model.k();
    let cache = args.cache.cache();
    let train = match &args.ipca_data {
        Some(dir) => {
            let source = DataSource::Folder(dir.clone());
            Dataset::load(&source, &cache, progress)
                .with_context(|| format!("loading IPCA's training data {}", source.label()))?
        }
        None => model_collections(&model.provenance().data_label, &cache, progress)?,
    };
    let refs: Vec<_> = train.tables.iter().collect();
    let basis = Arc::new(BaselineBasis::fit("IPCA", MappingKind::LogRelative, &refs, k, progress)?);
    let ipca = basis.codec(k)?;
    let deep = ModelCodec(&model);
    let source = match &args.data {
        Some(dir) => DataSource::Folder(dir.clone()),
        None => DataSource::Bundled(args.collection),
    };
    let shown = Dataset::load(&source, &cache, progress)
        .with_context(|| format!("loading the dataset {}", source.label()))?;
    // Shown materials the representations were fitted to (a model trained with
    // `--add-collections` names them `COLLECTION/NAME`): then the figure is in-sample.
    let seen = shown
        .names
        .iter()
        .filter(|n| {
            train.names.contains(n)
                || (args.data.is_none()
                    && train.names.contains(&format!("{}/{n}", args.collection.name())))
        })
        .count();
    let in_sample = (seen > 0).then(|| {
        format!(
            "{seen} of the {} shown materials are in the training data of both representations: \
             in-sample, not Fig. 9's generalization (give --model with a model trained on merl \
             alone)",
            shown.len()
        )
    });
    if let Some(note) = &in_sample {
        eprintln!("note: {note}");
    }

    let tonemap = Tonemap::default();
    let srgb = |img: &deepbrdf_render::Image| img.to_srgb8(&tonemap, [0, 0, 0]);
    let (mut originals, mut deeps, mut ipcas, mut rows) = (vec![], vec![], vec![], vec![]);
    progress.start(4 * shown.len() as u64, "rendering Fig. 9");
    for (name, table) in shown.names.iter().zip(&shown.tables) {
        let measure = ImageRelae::new(table, &config)?;
        progress.advance(1);
        let noise = measure.noise(table)?;
        progress.advance(1);
        let short = name.rsplit('/').next().unwrap_or(name).to_string();
        let mut row = Row { material: name.clone(), noise, deepbrdf: 0.0, ipca: 0.0 };
        for (label, codec, slot, out) in [
            ("DeepBRDF", &deep as &dyn Codec, &mut row.deepbrdf, &mut deeps),
            ("IPCA", &ipca as &dyn Codec, &mut row.ipca, &mut ipcas),
        ] {
            let reconstruction = codec.decode(&codec.encode(table)?)?;
            let image = measure.render(&reconstruction)?;
            *slot = relae(&image, measure.reference())?;
            out.push(Tile { image: srgb(&image), caption: format!("{label}: RelAE {:.3}", *slot) });
            progress.advance(1);
        }
        originals.push(Tile { image: srgb(measure.reference()), caption: short });
        rows.push(row);
    }
    progress.finish();
    let columns = rows.len() as u32;
    let tiles: Vec<Tile> = originals.into_iter().chain(deeps).chain(ipcas).collect();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let sheet = SheetConfig { columns, caption_height: 22, font_px: 15, ..Default::default() };
    contact_sheet(&tiles, &sheet)?.write_figure(&args.out.join("fig9.jpg"))?;

    let max_noise = rows.iter().map(|r| r.noise).fold(0.0, f64::max);
    let mut csv = String::from("material,render_noise,relae_deepbrdf,relae_ipca\n");
    let mut md = format!(
        "Fig. 9 on {} ({} materials), written by `experiments figures-generalize`: DeepBRDF \
         model {} (k = {k}, trained on {}) and IPCA at k = {k} fitted on {} ({} materials); \
         rows: as measured, DeepBRDF, IPCA; image RelAE on the preview sphere under sun and sky \
         ({size} px, {spp} spp, Sobol points, seed {seed}). Render noise: the image RelAE \
         between two renders of the measurement with seeds {seed} and {seed2}, at most \
         {max_noise:.4}; each reconstruction's render shares its random numbers with the \
         measurement's, so its noise is below that.\n\n\
         ![Fig. 9](fig9.jpg)\n\n| material | render noise | DeepBRDF | IPCA |\n\
         | --- | ---: | ---: | ---: |\n",
        shown.label,
        shown.len(),
        model.id(),
        model.provenance().data_label,
        train.label,
        train.len(),
        size = config.render.size,
        spp = config.render.spp,
        seed = config.render.seed,
        seed2 = config.next_seed().render.seed,
    );
    for r in &rows {
        writeln!(csv, "{},{:.6},{:.6},{:.6}", r.material, r.noise, r.deepbrdf, r.ipca)?;
        writeln!(md, "| {} | {:.4} | {:.4} | {:.4} |", r.material, r.noise, r.deepbrdf, r.ipca)?;
    }
    let (d, i) =
        (finite_mean(rows.iter().map(|r| r.deepbrdf)), finite_mean(rows.iter().map(|r| r.ipca)));
    let wins = rows.iter().filter(|r| r.deepbrdf < r.ipca).count();
    writeln!(md, "| **mean** | | **{d:.4}** | **{i:.4}** |")?;
    writeln!(md, "\nDeepBRDF is below IPCA on {wins} of {} materials.", rows.len())?;
    if let Some(note) = &in_sample {
        writeln!(md, "\n**Note**: {note}.")?;
    }
    write_atomic(&args.out.join("fig9.csv"), csv.as_bytes())?;
    write_atomic(&args.out.join("summary.md"), md.as_bytes())?;
    print!("{md}");
    eprintln!("wrote {}/fig9.jpg, fig9.csv, summary.md", args.out.display());
    Ok(())
}
