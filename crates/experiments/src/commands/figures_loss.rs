//! `experiments figures-loss --models DIR,DIR --data DIR [--show N]`: Fig. 4 of Hu et al.
//! (2020), the same network trained with eq. (4) under the L2 and the L1 norm (`experiments
//! train --loss l1`), each material rendered as measured and as each model reconstructs it
//! (eq. 2 then eq. 3), with the image RelAE under each tile (the harness's measure,
//! [`ImageRelae`], at the figure settings `--size`, `--spp`, `--seed`) and the renderer's noise
//! measured beside it. A shown material a model was trained on makes the figure in-sample; the
//! summary says so.
use crate::args::data::CacheArg;
use crate::editing::ModelCodec;
use anyhow::{bail, Context};
use deepbrdf_data::dataset::{DataSource, Dataset};
use deepbrdf_data::files::write_atomic;
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::figures::reconstruction_sheet::relae_caption;
use deepbrdf_eval::figures::{ReconstructionSheet, SheetInput};
use deepbrdf_eval::harness::Codec;
use deepbrdf_eval::metrics::ImageRelaeConfig;
use deepbrdf_eval::stats::finite_mean;
use deepbrdf_model::{DeepBrdf, TrainConfig};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The models to compare (comma-separated model directories), each labelled by the norm of
    /// its training configuration.
    #[arg(long, value_name = "DIR,...", value_delimiter = ',', required = true, num_args = 1..)]
    pub models: Vec<PathBuf>,
    /// The materials: a folder of MERL .binary files (e.g. a fold the models were not trained
    /// on: docs/reproducing.md).
    #[arg(long, value_name = "DIR")]
    pub data: PathBuf,
    /// Materials shown in the figure, evenly spaced through the folder's (all are measured).
    #[arg(long, value_name = "N", default_value_t = 6, value_parser = clap::value_parser!(u32).range(1..=32))]
    pub show: u32,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "results/fig4")]
    pub out: PathBuf,
    #[command(flatten)]
    pub figure: crate::args::figure::FigureArg,
    #[command(flatten)]
    pub cache: CacheArg,
}

/// The indices of `show` of `n` materials, evenly spaced from the first.
fn spaced(n: usize, show: usize) -> Vec<usize> {
    let show = show.min(n);
    (0..show).map(|i| i * n / show).collect()
}

/// A model and the label of its norm ("L2", "L1").
fn load(
    dir: &Path,
    device: &deepbrdf_model::burn::tensor::Device,
) -> anyhow::Result<(DeepBrdf, String)> {
    let model = DeepBrdf::load(dir, device)?;
    let config: TrainConfig = serde_json::from_value(model.provenance().train_config.clone())
        .with_context(|| format!("reading the training configuration of {}", dir.display()))?;
    Ok((model, config.norm().name().to_uppercase()))
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let config = args.figure.config()?;
    let device = crate::args::device::device()?;
    let mut models = Vec::with_capacity(args.models.len());
    for dir in &args.models {
        models.push(load(dir, &device)?);
    }
    if let Some((a, _)) = models.iter().find(|(m, _)| m.k() != models[0].0.k()) {
        bail!(
            "the models differ in k ({} and {}): compare models of one k",
            a.k(),
            models[0].0.k()
        );
    }
    let source = DataSource::Folder(args.data.clone());
    let data = Dataset::load(&source, &args.cache.cache(), progress)
        .with_context(|| format!("loading the materials {}", source.label()))?;
    let seen: Vec<&String> = data
        .names
        .iter()
        .filter(|n| models.iter().any(|(m, _)| m.provenance().trained_on(n)))
        .collect();
    let shown = spaced(data.len(), args.show as usize);

    let codecs: Vec<ModelCodec> = models.iter().map(|(m, _)| ModelCodec(m)).collect();
    let methods: Vec<(&str, &dyn Codec)> = models
        .iter()
        .zip(&codecs)
        .map(|((_, label), codec)| (label.as_str(), codec as &dyn Codec))
        .collect();
    let names: Vec<&str> = data.names.iter().map(String::as_str).collect();
    let tables: Vec<&MerlTable> = data.tables.iter().collect();
    let input = SheetInput {
        names: &names,
        tables: &tables,
        methods: &methods,
        config: &config,
        background: [0, 0, 0],
        caption: &relae_caption,
    };
    let sheet = ReconstructionSheet::measure(&input, progress).context("Fig. 4")?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    sheet.by_material(&shown)?.write_figure(&args.out.join("fig4.jpg"))?;
    let (csv, md) = texts(&models, &data, &source.label(), &shown, &seen, &sheet, &config)?;
    write_atomic(&args.out.join("fig4.csv"), csv.as_bytes())?;
    write_atomic(&args.out.join("summary.md"), md.as_bytes())?;
    print!("{md}");
    eprintln!("wrote {}/fig4.jpg, fig4.csv, summary.md", args.out.display());
    Ok(())
}

/// The figure's CSV and summary: per material its render noise and each model's image RelAE,
/// each model's mean and how often it is the lowest, and how the figure was made.
fn texts(
    models: &[(DeepBrdf, String)],
    data: &Dataset,
    source: &str,
    shown: &[usize],
    seen: &[&String],
    sheet: &ReconstructionSheet,
    config: &ImageRelaeConfig,
) -> anyhow::Result<(String, String)> {
    // errors[m][i]: model m on material i.
    let errors: Vec<&Vec<f64>> = sheet.columns.iter().map(|c| &c.relae).collect();
    let noise = &sheet.noise;

    let labels: Vec<&str> = models.iter().map(|(_, l)| l.as_str()).collect();
    let (csv, mut table) = per_material(&labels, &data.names, shown, noise, &errors)?;
    let means: Vec<f64> = errors.iter().map(|e| finite_mean(e.iter().copied())).collect();
    writeln!(
        table,
        "| **mean** | | {} |",
        means.iter().map(|m| format!("**{m:.4}**")).collect::<Vec<_>>().join(" | ")
    )?;
    let mut lines = String::new();
    for (m, (model, label)) in models.iter().enumerate() {
        let below = (0..data.len())
            .filter(|&i| (0..models.len()).all(|o| o == m || errors[m][i] < errors[o][i]))
            .count();
        writeln!(
            lines,
            "- {label}: model {} (k = {}, {} epochs on {} materials of {}), mean image RelAE \
             {:.4}, the lowest on {below} of {} materials.",
            model.id(),
            model.k(),
            model.provenance().epochs,
            model.provenance().materials.len(),
            model.provenance().data_label,
            means[m],
            data.len()
        )?;
    }
    let scope = match seen.len() {
        0 => "none of them seen by either model in training (held out)".to_string(),
        n => format!("**in-sample**: {n} of them are in a model's training data"),
    };
    let max_noise = noise.iter().copied().fold(0.0, f64::max);
    let md = format!(
        "Fig. 4 (L1 against L2 loss), written by `experiments figures-loss`: {} materials of \
         {}, {scope}; {} of them shown (rows: as measured, then each model's reconstruction). \
         Image RelAE on the preview sphere under sun and sky ({size} px, {spp} spp, Sobol points, \
         seed {seed}). Render noise: the image RelAE between two renders of the measurement with \
         seeds {seed} and {seed2}, at most {max_noise:.4}; each reconstruction's render shares \
         its random numbers with the measurement's, so its noise is below that.\n\n{lines}\n\
         ![Fig. 4](fig4.jpg)\n\n{table}",
        data.len(),
        source,
        shown.len(),
        size = config.render.size,
        spp = config.render.spp,
        seed = config.render.seed,
        seed2 = config.next_seed().render.seed,
    );
    Ok((csv, md))
}

/// Per material, its render noise and each model's image RelAE (`errors[m][i]`), as the
/// figure's CSV and the summary's table (without its mean row).
fn per_material(
    labels: &[&str],
    names: &[String],
    shown: &[usize],
    noise: &[f64],
    errors: &[&Vec<f64>],
) -> anyhow::Result<(String, String)> {
    let mut csv = format!(
        "material,shown,render_noise,{}\n",
        labels.iter().map(|l| format!("relae_{}", l.to_lowercase())).collect::<Vec<_>>().join(",")
    );
    let mut table = format!(
        "| material | render noise | {} |\n| --- | ---: |{}\n",
        labels.join(" | "),
        " ---: |".repeat(labels.len())
    );
    for (i, name) in names.iter().enumerate() {
        write!(csv, "{name},{},{:.6}", shown.contains(&i), noise[i])?;
        write!(
            table,
            "| {name}{} | {:.4} |",
            if shown.contains(&i) { " (shown)" } else { "" },
            noise[i]
        )?;
        for e in errors {
            write!(csv, ",{:.6}", e[i])?;
            write!(table, " {:.4} |", e[i])?;
        }
        csv.push('\n');
        table.push('\n');
    }
    Ok((csv, table))
}

#[cfg(test)]
mod tests {
    use super::spaced;

    #[test]
    fn shown_materials_are_spread_through_the_folder() {
        assert_eq!(spaced(20, 6), vec![0, 3, 6, 10, 13, 16]);
        assert_eq!(spaced(3, 6), vec![0, 1, 2]);
        assert_eq!(spaced(5, 1), vec![0]);
    }
}
