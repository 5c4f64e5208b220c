//! `experiments figures-generalize [--model DIR] [--collection rgl-measured | --data DIR]
//! [--baseline ipca | sun2018] [--materials LIST]`: Figs. 9 and 8 of Hu et al. (2020), one
//! kind of figure: each material rendered as measured, as DeepBRDF reconstructs it (eq. 2 then
//! eq. 3) and as a baseline does at the model's k, the baseline fitted on the model's training
//! data; the image RelAE of each reconstruction under its caption (the harness's measure,
//! [`ImageRelae`]: the preview sphere, sun and sky), rendered at the figure settings (`--size`,
//! `--spp`, `--seed`), with the renderer's noise measured beside it.
//!
//! - Fig. 9 (the default): IPCA, on materials no representation was fitted to (the seven real
//!   RGL measurements).
//! - Fig. 8 (`--baseline sun2018`): Sun et al. 2018's separation (1 diffuse + k - 1 specular
//!   coefficients), on `merl` materials with changing colour or complex lobes: in-sample, as
//!   the paper's figure, when the model was trained on them (said so in the summary).
use crate::args::data::{load_added, CacheArg};
use crate::args::model::ModelArg;
use crate::editing::ModelCodec;
use anyhow::{bail, Context};
use deepbrdf_data::bundled::Collection;
use deepbrdf_data::dataset::{DataSource, Dataset};
use deepbrdf_data::files::write_atomic;
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::baseline::BaselineMethod;
use deepbrdf_eval::figures::reconstruction_sheet::relae_caption;
use deepbrdf_eval::figures::{ReconstructionSheet, SheetInput};
use deepbrdf_eval::harness::{Codec, Method};
use deepbrdf_eval::metrics::ImageRelaeConfig;
use deepbrdf_eval::separation::SeparatedMethod;
use deepbrdf_eval::stats::finite_mean;
use deepbrdf_model::DeepBrdf;
use std::fmt::Write as _;
use std::path::PathBuf;

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
    /// Show only these materials of the collection or folder (comma-separated names).
    #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
    pub materials: Option<Vec<String>>,
    /// The baseline beside DeepBRDF: `ipca` (Fig. 9) or `sun2018` (Fig. 8).
    #[arg(long, value_enum, default_value = "ipca")]
    pub baseline: Baseline,
    /// Fit the baseline on this folder of MERL .binary files [default: the bundled
    /// collections the model was trained on].
    #[arg(long, value_name = "DIR")]
    pub ipca_data: Option<PathBuf>,
    /// Output folder [default: results/fig9, results/fig8 with `--baseline sun2018`].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub figure: crate::args::figure::FigureArg,
    #[command(flatten)]
    pub cache: CacheArg,
}

/// The baseline a figure compares DeepBRDF with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Baseline {
    /// IPCA (Nielsen et al. 2015): Fig. 9.
    Ipca,
    /// Sun et al. 2018's diffuse-specular separation: Fig. 8.
    Sun2018,
}

impl Baseline {
    /// The figure's number, its method's label and its CSV column.
    fn figure(self) -> (u32, &'static str, &'static str) {
        match self {
            Self::Ipca => (9, "IPCA", "relae_ipca"),
            Self::Sun2018 => (8, deepbrdf_eval::separation::NAME, "relae_sun2018"),
        }
    }

    /// The baseline at `k`, fitted on `train`.
    fn fit(
        self,
        train: &Dataset,
        k: usize,
        progress: &dyn Progress,
    ) -> anyhow::Result<Box<dyn Codec>> {
        let refs: Vec<_> = train.tables.iter().collect();
        let method: Box<dyn Method> = match self {
            Self::Ipca => Box::new(BaselineMethod::ipca()),
            Self::Sun2018 => Box::new(SeparatedMethod::default()),
        };
        Ok(method.fit(&refs, &train.names, k, progress)?)
    }
}

/// The baseline's training data when the model's: the bundled collections of its provenance label
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
             with its training materials, so that the baseline is fitted on the same data"
        );
    };
    let source = DataSource::Bundled(collections[0]);
    let mut train = Dataset::load(&source, cache, progress)
        .with_context(|| format!("loading the baseline's training data {}", source.label()))?;
    let added = load_added(&collections[1..], cache, progress)?;
    train.names.extend(added.names);
    train.tables.extend(added.tables);
    train.label = label.to_string();
    Ok(train)
}

/// The materials to show: the collection or folder, or the ones `--materials` names.
fn shown_materials(
    args: &Args,
    cache: &deepbrdf_data::cache::Cache,
    progress: &dyn Progress,
) -> anyhow::Result<Dataset> {
    let source = match &args.data {
        Some(dir) => DataSource::Folder(dir.clone()),
        None => DataSource::Bundled(args.collection),
    };
    let shown = Dataset::load(&source, cache, progress)
        .with_context(|| format!("loading the dataset {}", source.label()))?;
    let Some(names) = &args.materials else { return Ok(shown) };
    let mut picked = Dataset { label: shown.label.clone(), names: vec![], tables: vec![] };
    for name in names {
        let table = shown.get(name).with_context(|| {
            format!("--materials: '{name}' is not in {} ({} materials)", shown.label, shown.len())
        })?;
        picked.names.push(name.clone());
        picked.tables.push(table.clone());
    }
    Ok(picked)
}

/// A note where shown materials are in the representations' training data (a model trained
/// with `--add-collections` names them `COLLECTION/NAME`): then the figure is in-sample.
fn in_sample_note(args: &Args, train: &Dataset, shown: &Dataset) -> Option<String> {
    let seen = shown
        .names
        .iter()
        .filter(|n| {
            train.names.contains(n)
                || (args.data.is_none()
                    && train.names.contains(&format!("{}/{n}", args.collection.name())))
        })
        .count();
    (seen > 0).then(|| match args.baseline {
        Baseline::Ipca => format!(
            "{seen} of the {} shown materials are in the training data of both representations: \
             in-sample, not Fig. 9's generalization (give --model with a model trained on merl \
             alone)",
            shown.len()
        ),
        Baseline::Sun2018 => format!(
            "{seen} of the {} shown materials are in the training data of both representations: \
             in-sample, as the paper's Fig. 8",
            shown.len()
        ),
    })
}

/// The figure's words: its number, the baseline's label and CSV column, the image's file name
/// and the in-sample note, if any.
struct Text<'a> {
    figure: u32,
    label: &'a str,
    column: &'a str,
    image: &'a str,
    in_sample: Option<&'a str>,
}

impl Text<'_> {
    /// The figure's CSV and summary.
    fn write(
        &self,
        model: &DeepBrdf,
        train: &Dataset,
        shown: &Dataset,
        sheet: &ReconstructionSheet,
        config: &ImageRelaeConfig,
    ) -> anyhow::Result<(String, String)> {
        let Text { figure, label, column, image, in_sample } = *self;
        let k = model.k();
        let rows: Vec<Row> = (0..shown.len())
            .map(|s| Row {
                material: shown.names[s].clone(),
                noise: sheet.noise[s],
                deepbrdf: sheet.columns[0].relae[s],
                baseline: sheet.columns[1].relae[s],
            })
            .collect();
        let max_noise = rows.iter().map(|r| r.noise).fold(0.0, f64::max);
        let mut csv = format!("material,render_noise,relae_deepbrdf,{column}\n");
        let mut md = format!(
            "Fig. {figure} on {} ({} materials), written by `experiments figures-generalize`: \
             DeepBRDF model {} (k = {k}, trained on {}) and {label} at k = {k} fitted on {} ({} \
             materials); rows: as measured, DeepBRDF, {label}; image RelAE on the preview sphere \
             under sun and sky \
             ({size} px, {spp} spp, Sobol points, seed {seed}). Render noise: the image RelAE \
             between two renders of the measurement with seeds {seed} and {seed2}, at most \
             {max_noise:.4}; each reconstruction's render shares its random numbers with the \
             measurement's, so its noise is below that.\n\n\
             ![Fig. {figure}]({image})\n\n| material | render noise | DeepBRDF | {label} |\n\
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
            writeln!(csv, "{},{:.6},{:.6},{:.6}", r.material, r.noise, r.deepbrdf, r.baseline)?;
            writeln!(
                md,
                "| {} | {:.4} | {:.4} | {:.4} |",
                r.material, r.noise, r.deepbrdf, r.baseline
            )?;
        }
        let d = finite_mean(rows.iter().map(|r| r.deepbrdf));
        let b = finite_mean(rows.iter().map(|r| r.baseline));
        let wins = rows.iter().filter(|r| r.deepbrdf < r.baseline).count();
        writeln!(md, "| **mean** | | **{d:.4}** | **{b:.4}** |")?;
        writeln!(md, "\nDeepBRDF is below {label} on {wins} of {} materials.", rows.len())?;
        if let Some(note) = in_sample {
            writeln!(md, "\n**Note**: {note}.")?;
        }
        Ok((csv, md))
    }
}

/// One material's row.
struct Row {
    material: String,
    noise: f64,
    deepbrdf: f64,
    baseline: f64,
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
            Dataset::load(&source, &cache, progress).with_context(|| {
                format!("loading the baseline's training data {}", source.label())
            })?
        }
        None => model_collections(&model.provenance().data_label, &cache, progress)?,
    };
    let (figure, label, column) = args.baseline.figure();
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from(format!("results/fig{figure}")));
    let deep = ModelCodec(&model);
    let shown = shown_materials(&args, &cache, progress)?;
    // Fitted once the materials to show are known (a wrong name costs no fit).
    let baseline = args.baseline.fit(&train, k, progress)?;
    let in_sample = in_sample_note(&args, &train, &shown);
    if let Some(note) = &in_sample {
        eprintln!("note: {note}");
    }

    let names: Vec<&str> = shown.names.iter().map(|n| n.rsplit('/').next().unwrap_or(n)).collect();
    let tables: Vec<&MerlTable> = shown.tables.iter().collect();
    let methods: [(&str, &dyn Codec); 2] = [("DeepBRDF", &deep), (label, baseline.as_ref())];
    let input = SheetInput {
        names: &names,
        tables: &tables,
        methods: &methods,
        config: &config,
        background: [0, 0, 0],
        caption: &relae_caption,
    };
    let sheet =
        ReconstructionSheet::measure(&input, progress).with_context(|| format!("Fig. {figure}"))?;
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let image = format!("fig{figure}.jpg");
    sheet.by_method()?.write_figure(&out.join(&image))?;
    let text = Text { figure, label, column, image: &image, in_sample: in_sample.as_deref() };
    let (csv, md) = text.write(&model, &train, &shown, &sheet, &config)?;
    write_atomic(&out.join(format!("fig{figure}.csv")), csv.as_bytes())?;
    write_atomic(&out.join("summary.md"), md.as_bytes())?;
    print!("{md}");
    eprintln!("wrote {}/fig{figure}.jpg, fig{figure}.csv, summary.md", out.display());
    Ok(())
}
