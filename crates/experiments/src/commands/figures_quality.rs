//! `experiments figures-quality [--model DIR] [--collection merl | --data DIR] [--out
//! results/fig5-6]`: Figs. 5 and 6 of Hu et al. (2020).
//!
//! - Fig. 5 (§3.3): every material of the dataset encoded by the model, the latents projected
//!   onto their first two principal components and drawn as a scatter plot
//!   ([`LatentMap`]).
//! - Fig. 6 (§4): a few materials rendered as measured, as DeepBRDF reconstructs them (at the
//!   model's k) and as PCA and IPCA do at several k, both fitted here on the dataset, with the
//!   image RelAE of each and the renderer's noise ([`ReconstructionSheet`]), at a size and
//!   sample count where the renderer's grain is not visible (Sobol points).
//!
//! Like the paper's figures both are in-sample by default: the shipped model and PCA and IPCA
//! fitted on the whole dataset have seen every material shown. `--held-out` fits PCA and IPCA
//! without the Fig. 6 materials and refuses a model trained on any of them.
use crate::args::data::DataArgs;
use crate::args::model::ModelArg;
use crate::editing::ModelCodec;
use anyhow::{bail, Context};
use deepbrdf_data::dataset::Dataset;
use deepbrdf_data::files::write_atomic;
use deepbrdf_data::{MerlTable, Progress, Silent};
use deepbrdf_eval::baseline::{BaselineCodec, BaselineMethod};
use deepbrdf_eval::figures::latent_map::{THUMB_SIZE, THUMB_SPP};
use deepbrdf_eval::figures::reconstruction_sheet::{relae_caption_with_k, sheet_config};
use deepbrdf_eval::figures::{LatentMap, LatentMapInput, ReconstructionSheet, SheetInput};
use deepbrdf_eval::harness::{Codec, Method as _};
use deepbrdf_eval::metrics::ImageRelaeConfig;
use deepbrdf_model::DeepBrdf;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArg,
    #[command(flatten)]
    pub data: DataArgs,
    /// Fig. 6's materials, by name in the dataset (a diffuse, a plastic, a metal and a paint by
    /// default).
    #[arg(
        long,
        value_name = "NAME,...",
        value_delimiter = ',',
        default_value = "blue-fabric,red-specular-plastic,nickel,gold-metallic-paint"
    )]
    pub materials: Vec<String>,
    /// Fig. 6's numbers of PCA and IPCA components (each one adds two columns; `5,10,20,40` for
    /// a finer sweep, three by default to keep the committed figure small).
    #[arg(long = "k", value_name = "K,...", value_delimiter = ',', default_value = "5,10,40")]
    pub ks: Vec<usize>,
    /// Fig. 6's renders.
    #[command(flatten)]
    pub figure: crate::args::figure::FigureArg,
    /// Fig. 5: at most this many materials shown as a render with their name.
    #[arg(long, default_value_t = 24)]
    pub labels: usize,
    /// Fig. 6 held out: fit PCA and IPCA without its materials, and refuse a model trained on
    /// any of them.
    #[arg(long)]
    pub held_out: bool,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "results/fig5-6")]
    pub out: PathBuf,
}

/// The checked choice of Fig. 6: its materials (indices into the set), PCA's and IPCA's ks
/// (ascending) and their training tables.
struct Choice<'a> {
    shown: Vec<usize>,
    ks: Vec<usize>,
    fit: Vec<&'a MerlTable>,
}

impl<'a> Choice<'a> {
    fn of(args: &Args, set: &'a Dataset) -> anyhow::Result<Self> {
        let mut ks = args.ks.clone();
        ks.sort_unstable();
        ks.dedup();
        if ks.is_empty() || ks[0] == 0 {
            bail!("--k must list at least one number of components, each at least 1");
        }
        if args.materials.is_empty() {
            bail!("--materials must name at least one material");
        }
        let n = set.len();
        let shown: Vec<usize> = args
            .materials
            .iter()
            .map(|m| {
                set.names.iter().position(|n| n == m).with_context(|| {
                    format!("--materials: '{m}' is not in {} ({n} materials)", set.label)
                })
            })
            .collect::<anyhow::Result<_>>()?;
        let fit: Vec<&MerlTable> = (0..n)
            .filter(|i| !(args.held_out && shown.contains(i)))
            .map(|i| &set.tables[i])
            .collect();
        let k_max = ks[ks.len() - 1];
        if k_max + 1 > fit.len() {
            bail!(
                "--k {k_max}: PCA of {} materials has at most {} components",
                fit.len(),
                fit.len().saturating_sub(1)
            );
        }
        Ok(Self { shown, ks, fit })
    }
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let started = Instant::now();
    let device = crate::args::device::device()?;
    let model_dir = args.model.dir()?;
    let model = DeepBrdf::load(&model_dir, &device)
        .with_context(|| format!("loading the model {}", model_dir.display()))?;
    let set = args.data.load(progress)?;
    let choice = Choice::of(&args, &set)?;
    let names: Vec<&str> = choice.shown.iter().map(|&i| set.names[i].as_str()).collect();
    let seen: Vec<&str> =
        names.iter().copied().filter(|m| model.provenance().trained_on(m)).collect();
    if args.held_out && !seen.is_empty() {
        bail!(
            "--held-out: the model {} was trained on {}; give --model with a model trained \
             without them",
            model_dir.display(),
            seen.join(", ")
        );
    }
    let config = args.figure.config()?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let deep = ModelCodec(&model);
    let (names_all, tables) = (&set.names, &set.tables);
    let input = LatentMapInput {
        label: &set.label,
        names: names_all,
        tables,
        codec: &deep,
        config: &config,
        labels: args.labels,
    };
    let map = LatentMap::draw(&input, progress).context("Fig. 5")?;
    map.image.write_png(&args.out.join("fig5.png"))?;
    write_atomic(&args.out.join("fig5.csv"), map.csv(names_all).as_bytes())?;
    let tables: Vec<&MerlTable> = choice.shown.iter().map(|&i| &set.tables[i]).collect();
    let k_max = choice.ks[choice.ks.len() - 1];
    let mut codecs: Vec<(String, Box<dyn Codec>)> = vec![("DeepBRDF".into(), Box::new(deep))];
    for method in [BaselineMethod::pca(), BaselineMethod::ipca()] {
        let basis = Arc::new(method.fit_basis(&choice.fit, k_max, &Silent)?);
        for codec in BaselineCodec::nested(&basis, &choice.ks)? {
            codecs.push((method.name(), Box::new(codec)));
        }
    }
    let methods: Vec<(&str, &dyn Codec)> =
        codecs.iter().map(|(label, codec)| (label.as_str(), codec.as_ref())).collect();
    let background = sheet_config(0).background;
    let input = SheetInput {
        names: &names,
        tables: &tables,
        methods: &methods,
        config: &config,
        background,
        caption: &relae_caption_with_k,
    };
    let sheet = ReconstructionSheet::measure(&input, progress).context("Fig. 6")?;
    let rows: Vec<usize> = (0..names.len()).collect();
    sheet.by_material(&rows)?.write_figure(&args.out.join("fig6.jpg"))?;
    let (csv6, table) = fig6_csv_and_table(&sheet, &names);
    write_atomic(&args.out.join("fig6.csv"), csv6.as_bytes())?;
    let md = summary(&args, &model, &set, &choice, &seen, &map, &sheet, &config, &table, started);
    write_atomic(&args.out.join("summary.md"), md.as_bytes())?;
    print!("{md}");
    eprintln!("wrote {}/fig5.png, fig5.csv, fig6.jpg, fig6.csv, summary.md", args.out.display());
    Ok(())
}

/// `fig6.csv` and the summary's table: per material the render noise and each column's image
/// RelAE.
fn fig6_csv_and_table(sheet: &ReconstructionSheet, names: &[&str]) -> (String, String) {
    let mut csv = String::from("material,render_noise");
    let mut table = String::from("| material | render noise |");
    for c in &sheet.columns {
        let _ = write!(csv, ",{}_{}", c.label.to_lowercase(), c.k);
        let _ = write!(table, " {} {}D |", c.label, c.k);
    }
    csv.push('\n');
    table += "\n| --- | ---: |";
    table += &" ---: |".repeat(sheet.columns.len());
    table.push('\n');
    for (s, name) in names.iter().enumerate() {
        let _ = write!(csv, "{name},{:.6}", sheet.noise[s]);
        let _ = write!(table, "| {name} | {:.4} |", sheet.noise[s]);
        for c in &sheet.columns {
            let _ = write!(csv, ",{:.6}", c.relae[s]);
            let _ = write!(table, " {:.4} |", c.relae[s]);
        }
        csv.push('\n');
        table.push('\n');
    }
    (csv, table)
}

/// The summary: how the figures were made, what they show, and Fig. 6's table.
#[allow(clippy::too_many_arguments)]
fn summary(
    args: &Args,
    model: &DeepBrdf,
    set: &Dataset,
    choice: &Choice,
    seen: &[&str],
    map: &LatentMap,
    sheet: &ReconstructionSheet,
    config: &ImageRelaeConfig,
    table: &str,
    started: Instant,
) -> String {
    let (n, k, shown) = (set.len(), model.k(), choice.shown.len());
    let settings = config.render;
    let model_scope = match seen.len() {
        0 => "the model was not trained on any of them".to_string(),
        s if s == shown => format!(
            "the model was trained on all {shown} (its training data: {})",
            model.provenance().data_label
        ),
        s => format!("the model was trained on {s} of them ({})", seen.join(", ")),
    };
    let baseline_scope = if args.held_out {
        format!("PCA and IPCA fitted on the other {} materials of {}", choice.fit.len(), set.label)
    } else {
        format!(
            "PCA and IPCA fitted on all {n} materials of {}, the shown ones included",
            set.label
        )
    };
    let scope = if args.held_out { "held out" } else { "in-sample, as in the paper" };
    let max_noise = sheet.noise.iter().copied().fold(0.0, f64::max);
    let percent = |f: f64| 100.0 * f;
    let (x_share, y_share) = (percent(map.plane.explained[0]), percent(map.plane.explained[1]));
    format!(
        "# Figs. 5 and 6\n\nWritten by `experiments figures-quality` with model {id} (k = {k}, \
         trained on {data}) on {label} ({n} materials), {secs:.0} s.\n\n\
         ## Fig. 5: the latent space\n\n![Fig. 5](fig5.png)\n\n\
         Every material of {label} encoded by the model (its refined latent, eq. 2), the {n} \
         latents of {k} values projected onto their first two principal components (PCA of the \
         latents, eq. 5): {x_share:.1}% and {y_share:.1}% of their variance. Each dot is in the \
         mean colour of the material's render on the preview sphere; {shown_labels} of them \
         (chosen to spread over the plane) are shown as that render ({THUMB_SIZE} px, \
         {THUMB_SPP} spp) with their name. The paper's Fig. 5 is a diagram of the same idea: the \
         autoencoder maps the measured BRDFs onto a low-dimensional manifold. In-sample: the \
         model's training data is {data}. Coordinates and latents: `fig5.csv`.\n\n\
         ## Fig. 6: reconstruction quality\n\n![Fig. 6](fig6.jpg)\n\n\
         Rows: {materials}; columns: the measurement, DeepBRDF at k = {k}, PCA (log of the \
         reflectance) and IPCA (Nielsen et al.'s log-relative mapping) at k = {ks}. Under each \
         reconstruction its image RelAE against the measurement's render (the preview sphere \
         under sun and sky, {size} px, {spp} spp, Sobol points, seed {seed}; each \
         reconstruction rendered with the measurement's seed and sampling). {scope_cap}: \
         {model_scope}; {baseline_scope}.\n\n\
         Render noise: the image RelAE between two renders of the measurement with seeds \
         {seed} and {seed2}, at most {max_noise:.4}; each reconstruction's RelAE shares its \
         render's random numbers with the measurement's, so its noise is below that.\n\n{table}",
        id = model.id(),
        data = model.provenance().data_label,
        label = set.label,
        secs = started.elapsed().as_secs_f64(),
        shown_labels = map.labelled.len(),
        materials = args.materials.join(", "),
        ks = choice.ks.iter().map(usize::to_string).collect::<Vec<_>>().join(", "),
        size = settings.size,
        spp = settings.spp,
        seed = settings.seed,
        seed2 = config.next_seed().render.seed,
        scope_cap = capitalise(scope),
    )
}

/// `s` with its first letter upper-case.
fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    c.next().map_or_else(String::new, |f| f.to_uppercase().chain(c).collect())
}
