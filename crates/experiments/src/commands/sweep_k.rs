//! `experiments sweep-k`: the main job. Runs PCA and IPCA at each k (default 5, 10, 20, 40) and
//! DeepBRDF at the k of `--deep-ks` (default 10) on the bundled `merl` collection through the
//! evaluation harness, measures the robustness to missing phi_d slices (Fig. 2), and writes
//! tables and plots (Figs. 2, 3 and 7) to one folder.
//!
//! By default held out: 5-fold over the materials, each fold's 20 scored by methods fitted on
//! the other 80, the `slice` preset trained once per fold at k = 10 (five models;
//! docs/results.md has the times), image RelAE included. The paper's in-sample protocol
//! (Fig. 3) is `--mode in-sample`.
//!
//! Models are trained into `<out>/models/fold<F>/k<K>` with resume on: rerunning an interrupted
//! sweep continues where it stopped, and finished models are loaded, not retrained.
use crate::args::data::DataArgs;
use crate::progress_log::ProgressLog;
use crate::readme_block;
use anyhow::{bail, Context};
use deepbrdf_data::bundled::Collection;
use deepbrdf_data::dataset::Dataset;
use deepbrdf_data::files::write_atomic;
use deepbrdf_data::table_set::{StreamedDataset, TableSet};
use deepbrdf_data::Progress;
use deepbrdf_eval::baseline::BaselineMethod;
use deepbrdf_eval::deep::{DeepMethod, NAME};
use deepbrdf_eval::figures::slices::{self as slices_figure, FIG2_MATERIAL};
use deepbrdf_eval::harness::{
    self, AtKs, HarnessConfig, Materials, Measure, Method, Mode, Results,
};
use deepbrdf_eval::robustness::{self, Robustness};
use deepbrdf_eval::saved_sweep::SavedSweep;
use deepbrdf_eval::sweep_report::{minutes, training_csv, SweepReport};
use deepbrdf_model::{Preset, TrainConfig};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Marker lines of the README block this command writes (`--update-readme`): one block per
/// mode, so the held-out block the default run writes and the in-sample block of the paper's
/// protocol live side by side.
pub fn readme_markers(mode: Mode) -> (&'static str, &'static str) {
    match mode {
        Mode::KFold { .. } => ("<!-- sweep-k:begin -->", "<!-- sweep-k:end -->"),
        Mode::InSample => ("<!-- sweep-k-in-sample:begin -->", "<!-- sweep-k-in-sample:end -->"),
        Mode::Generalize => {
            ("<!-- sweep-k-generalize:begin -->", "<!-- sweep-k-generalize:end -->")
        }
    }
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Latent dimensions k of PCA and IPCA (comma separated).
    #[arg(long, value_delimiter = ',', default_values_t = [5, 10, 20, 40])]
    pub ks: Vec<usize>,
    /// The k of --ks at which DeepBRDF is trained and scored (a network per fold and k):
    /// comma separated, or `all` [default: 10 when swept, else the middle k].
    #[arg(long, value_name = "LIST")]
    pub deep_ks: Option<String>,
    /// Network and training preset: `slice` (one network shared by the phi_d slices, the
    /// shipped model's) or `paper` (Table 1 and §3.2's training, for a GPU).
    #[arg(long, default_value = "slice")]
    pub preset: Preset,
    #[command(flatten)]
    pub refine: crate::args::refine::RefineArg,
    /// Train with this configuration instead of a preset (JSON, as a run's `train_config.json`);
    /// its k is replaced by each k of the sweep.
    #[arg(long, value_name = "FILE")]
    pub train_config: Option<PathBuf>,
    /// Override the number of training epochs.
    #[arg(long, value_name = "N")]
    pub epochs: Option<usize>,
    /// `in-sample` (fit and evaluate on all materials, the paper's Fig. 3), `kfold:N` (each
    /// material evaluated by models that never saw it) or `generalize` (fit on the data,
    /// evaluate on --eval-collections: Fig. 9).
    #[arg(long, default_value = "kfold:5")]
    pub mode: Mode,
    /// Generalize mode: the bundled collections to evaluate on (comma-separated) [default:
    /// rgl-measured, the real measurements].
    #[arg(long, value_delimiter = ',', value_name = "NAME,...")]
    pub eval_collections: Option<Vec<Collection>>,
    /// Output folder [default: runs/sweep-k, runs/sweep-k-kfoldN in k-fold mode,
    /// runs/sweep-k-generalize; `runs/` is not tracked, so a run never replaces the committed
    /// results: `--out results/sweep-k-kfold5` refreshes them].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Measures (comma-separated): mapped_mse (eq. 1 space, the paper's training loss),
    /// cos_rmse, image_relae (renders of the preview sphere under sun and sky, Fig. 7 in image
    /// space; ~0.3 s of CPU per reconstruction), and the highlight's defects, counted:
    /// dark_hole (a dark dot at the highlight's centre), tinted_centre (its colour moved).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "mapped_mse,cos_rmse,image_relae,dark_hole,tinted_centre"
    )]
    pub measures: Vec<Measure>,
    /// Seed of the training runs and of the k-fold split.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    #[command(flatten)]
    pub data: DataArgs,
    /// Use only the first N materials (in name order).
    #[arg(long, value_name = "N")]
    pub limit: Option<usize>,
    /// The k values whose models are evaluated on reduced inputs (Fig. 2): a comma-separated
    /// list of DeepBRDF's k, or `all` [default: 10 when swept, else the middle k].
    #[arg(long, value_name = "LIST")]
    pub fig2_ks: Option<String>,
    /// The material shown in the Fig. 2 picture of slices.
    #[arg(long, value_name = "NAME", default_value = FIG2_MATERIAL)]
    pub fig2_material: String,
    /// Rewrite the block between `<!-- sweep-k:begin -->` and `<!-- sweep-k:end -->` in this
    /// markdown file (e.g. README.md) with the results table and plots.
    #[arg(long, value_name = "FILE")]
    pub update_readme: Option<PathBuf>,
    /// Train and evaluate nothing: redraw the charts of the finished run in DIR from its CSV
    /// files and, with --update-readme, rewrite its block from them (its mode picks the block).
    #[arg(long, value_name = "DIR")]
    pub from: Option<PathBuf>,
}

impl Args {
    /// The training configuration of each k.
    fn config_for(&self) -> anyhow::Result<Box<dyn Fn(usize) -> TrainConfig + Send + Sync>> {
        let base = match &self.train_config {
            Some(path) => Some(TrainConfig::from_file(path)?),
            None => None,
        };
        let (preset, epochs, seed) = (self.preset, self.epochs, self.seed);
        let config_for = move |k: usize| {
            let mut config = match &base {
                Some(base) => base.clone(),
                None => preset.train_config(k),
            };
            config.model.latent = k;
            if let Some(epochs) = epochs {
                config.epochs = epochs;
            }
            config.seed = seed;
            config
        };
        for k in self.deep_ks()? {
            config_for(k)
                .validate()
                .with_context(|| format!("the training configuration for k = {k}"))?;
        }
        Ok(Box::new(config_for))
    }

    /// The k at which DeepBRDF is trained and scored.
    fn deep_ks(&self) -> anyhow::Result<Vec<usize>> {
        k_list("--deep-ks", self.deep_ks.as_deref(), &self.ks)
    }

    /// The k values of the Fig. 2 evaluation.
    fn fig2_ks(&self) -> anyhow::Result<Vec<usize>> {
        k_list("--fig2-ks", self.fig2_ks.as_deref(), &self.deep_ks()?)
    }

    fn out_dir(&self) -> PathBuf {
        self.out.clone().unwrap_or_else(|| match self.mode {
            Mode::KFold { folds } => PathBuf::from(format!("runs/sweep-k-kfold{folds}")),
            Mode::Generalize => PathBuf::from("runs/sweep-k-generalize"),
            _ => PathBuf::from("runs/sweep-k"),
        })
    }

    /// The training materials, their tables streamed from the table cache (or their files)
    /// where they can be: the sweep reads each table when it needs it.
    /// The DeepBRDF models held in memory for Fig. 2 (at `fig2_ks`): none in k-fold mode, where
    /// the models of earlier folds are loaded again when the robustness step needs them.
    fn retained<'a>(&self, fig2_ks: &'a [usize]) -> &'a [usize] {
        match self.mode {
            Mode::KFold { .. } => &[],
            _ => fig2_ks,
        }
    }

    /// The harness' settings, checked (with `--eval-collections` only in generalize mode).
    fn harness_config(&self) -> anyhow::Result<HarnessConfig> {
        if self.mode != Mode::Generalize && self.eval_collections.is_some() {
            bail!("--eval-collections is for generalize mode only");
        }
        let config = HarnessConfig {
            ks: self.ks.clone(),
            mode: self.mode,
            seed: self.seed,
            measures: self.measures.clone(),
            only_fold: None,
        };
        config.validate()?;
        Ok(config)
    }

    /// Generalize mode's evaluation collections (the real RGL measurements by default).
    fn load_eval(&self, progress: &dyn Progress) -> anyhow::Result<Option<Dataset>> {
        if self.mode != Mode::Generalize {
            return Ok(None);
        }
        let collections =
            self.eval_collections.clone().unwrap_or_else(|| vec![Collection::RglMeasured]);
        Ok(Some(crate::args::data::load_collections(&collections, &self.data, progress)?))
    }

    fn load_data(&self, progress: &dyn Progress) -> anyhow::Result<StreamedDataset> {
        let mut data = self.data.load_streamed(progress)?;
        if let Some(n) = self.limit {
            if n == 0 {
                bail!("--limit 0 leaves no material");
            }
            data.truncate(n);
            data.label = format!("{} (first {})", data.label, data.names.len());
        }
        Ok(data)
    }
}

pub fn run(args: Args, quiet: bool, bars: &dyn Progress) -> anyhow::Result<()> {
    if let Some(dir) = &args.from {
        return from_saved(dir, args.update_readme.as_deref());
    }
    let started = Instant::now();
    let logged = ProgressLog::new(bars, quiet, Duration::from_secs(30));
    let progress: &dyn Progress = &logged;
    let harness_config = args.harness_config()?;
    let config_for = args.config_for()?;
    let deep_ks = args.deep_ks()?;
    let fig2_ks = args.fig2_ks()?;
    let kind = crate::args::device::kind()?;
    let device = crate::args::device::device()?;
    let out = args.out_dir();
    // Held until the sweep ends: a second run on the same folder is refused.
    let _lock = deepbrdf_data::lock::FolderLock::acquire(&out)?;
    let models_dir = out.join("models");

    let data = args.load_data(progress)?;
    let eval = args.load_eval(progress)?;
    let loaded_at = started.elapsed().as_secs_f64();
    let training = training_label(&args, &config_for(deep_ks[0]), &kind.to_string());
    announce(&args, &data, &deep_ks, &training, &out);

    let (pca, ipca) = (BaselineMethod::pca(), BaselineMethod::ipca());
    let deep = DeepMethod::new(config_for, &models_dir, &data.label, device.clone())
        .retaining(args.retained(&fig2_ks))
        .refining(args.refine.refinement()?);
    let materials = Materials { names: &data.names, tables: data.tables(), label: &data.label };
    let eval_label = eval.as_ref().map(|e| format!("{} ({} materials)", e.label, e.len()));
    let eval_materials = eval.as_ref().zip(eval_label.as_deref()).map(|(e, label)| Materials {
        names: &e.names,
        tables: &e.tables,
        label,
    });
    let methods: [&dyn Method; 3] = [&pca, &ipca, &AtKs::new(&deep, &deep_ks)];
    let results = harness::run(&methods, &harness_config, materials, eval_materials, progress)?;
    results.write(&out)?;

    // Fig. 2's reduced inputs, on the materials each fold's models are scored on.
    let scored: (&[String], &dyn TableSet) = match &eval {
        Some(e) => (&e.names, &e.tables),
        None => (&data.names, data.tables()),
    };
    let fig2 = Fig2 { ks: &fig2_ks, deep: &deep, out: &out };
    let (robustness, fig2) = fig2.measure(&args, scored, data.names.len(), &results, progress)?;
    let fits = deep.fits();
    write_atomic(&out.join("training.csv"), training_csv(&fits).as_bytes())?;

    let wall = started.elapsed().as_secs_f64();
    let report = SweepReport {
        results: &results,
        deep_ks: &deep_ks,
        robustness: &robustness,
        fits: &fits,
        training: &training,
        fig2: fig2.as_deref(),
        loaded_at,
        wall,
    };
    write_report(&args, &report, &out)
}

/// Prints what the sweep is about to do.
fn announce(args: &Args, data: &StreamedDataset, deep_ks: &[usize], training: &str, out: &Path) {
    println!(
        "sweep-k: {} materials ({}), PCA and IPCA at k = {:?}, DeepBRDF at k = {deep_ks:?}, {} mode, {training}; output in {}",
        data.names.len(),
        data.label,
        args.ks,
        args.mode,
        out.display()
    );
}

/// How DeepBRDF is trained, for the report: the preset or configuration file, and `sample`'s
/// (the first k's) epochs, batch, learning rate, the seed and the device.
fn training_label(args: &Args, sample: &TrainConfig, device: &str) -> String {
    let training = match &args.train_config {
        Some(path) => format!("configuration {}", path.display()),
        None => format!("preset {}", args.preset),
    };
    format!(
        "{training}, {} epochs, batch {}, lr {:.1e}, seed {}, device {device}",
        sample.epochs, sample.batch_size, sample.learning_rate, args.seed
    )
}

/// Writes the summary (and the README's results block where asked) and prints the report.
fn write_report(args: &Args, report: &SweepReport, out: &Path) -> anyhow::Result<()> {
    write_atomic(&out.join("summary.md"), report.summary_markdown().as_bytes())?;
    if let Some(readme) = &args.update_readme {
        let block = report.readme_block(&relative_link(readme, out)?);
        let (begin, end) = readme_markers(args.mode);
        readme_block::update_file(readme, begin, end, &block)?;
        println!("updated the results block of {}", readme.display());
    }
    print!("{}", report.printed());
    println!("wrote {}; total wall time {}", out.display(), minutes(report.wall));
    Ok(())
}

/// `--from DIR`: the charts of the run in `dir` redrawn and, with `readme`, its block
/// rewritten, from the run's files.
fn from_saved(dir: &Path, readme: Option<&Path>) -> anyhow::Result<()> {
    let saved = SavedSweep::read(dir)?;
    saved.results.write_charts(dir)?;
    println!("redrew the charts of {} from its results.csv", dir.display());
    if let Some(readme) = readme {
        let (begin, end, block) = saved_block(&saved, readme, dir)?;
        readme_block::update_file(readme, begin, end, &block)?;
        println!("updated the results block of {}", readme.display());
    }
    Ok(())
}

/// The markers and the text of the block of `readme` for the run `saved` read from `dir`.
pub fn saved_block(
    saved: &SavedSweep,
    readme: &Path,
    dir: &Path,
) -> anyhow::Result<(&'static str, &'static str, String)> {
    let (begin, end) = readme_markers(saved.results.mode);
    Ok((begin, end, saved.report().readme_block(&relative_link(readme, dir)?)))
}

/// The Fig. 2 picture for `--fig2-material` (skipped with a note when it is not in the data),
/// at `k` (the first of the Fig. 2 k), by the model of the fold that evaluates it.
/// Fig. 2: the DeepBRDF models' errors from reduced inputs at `ks` (the first also drawn).
struct Fig2<'a> {
    ks: &'a [usize],
    deep: &'a DeepMethod,
    out: &'a Path,
}

impl Fig2<'_> {
    /// The robustness table over `scored` (written to the output) and the picture's file, if
    /// its material is scored; `trained` materials in the training set.
    fn measure(
        &self,
        args: &Args,
        scored: (&[String], &dyn TableSet),
        trained: usize,
        results: &Results,
        progress: &dyn Progress,
    ) -> anyhow::Result<(Robustness, Option<String>)> {
        let folds = args.mode.folds(trained, scored.0.len(), args.seed)?;
        let robustness =
            robustness::measure(scored.0, scored.1, &folds, self.deep, self.ks, results, progress)?;
        robustness.write(self.out)?;
        let picture = fig2_picture(args, self.ks[0], scored, &folds, self.deep, self.out)?;
        Ok((robustness, picture))
    }
}

fn fig2_picture(
    args: &Args,
    k: usize,
    (names, tables): (&[String], &dyn TableSet),
    folds: &[harness::Fold],
    deep: &DeepMethod,
    out: &Path,
) -> anyhow::Result<Option<String>> {
    let Some(i) = names.iter().position(|n| n == &args.fig2_material) else {
        println!("note: {} is not among the materials; no Fig. 2 picture", args.fig2_material);
        return Ok(None);
    };
    let fold = folds.iter().find(|f| f.test.contains(&i)).map_or(0, |f| f.index);
    let model = deep
        .model(fold, k)
        .with_context(|| format!("no {NAME} model was fitted for fold {fold} at k = {k}"))?;
    let table = tables.table(i)?;
    slices_figure::write(&model, &table, &out.join("fig2_slices.png"))?;
    Ok(Some(format!("{} (k = {k})", args.fig2_material)))
}

/// A list of k given as `arg` (comma separated, or `all` for every k of `among`), each of
/// `among`; without one, 10 when among them, else the middle one.
fn k_list(flag: &str, arg: Option<&str>, among: &[usize]) -> anyhow::Result<Vec<usize>> {
    let default = if among.contains(&10) { 10 } else { among[among.len() / 2] };
    let ks = match arg.map(str::trim) {
        None => vec![default],
        Some("all") => among.to_vec(),
        Some(list) => list
            .split(',')
            .map(|k| k.trim().parse::<usize>())
            .collect::<Result<Vec<_>, _>>()
            .map_err(|_| {
                anyhow::anyhow!("{flag} {list:?}: expected `all` or k values such as 10,20")
            })?,
    };
    if let Some(k) = ks.iter().find(|k| !among.contains(k)) {
        bail!("{flag}: k = {k} is not among {among:?}");
    }
    if ks.is_empty() {
        bail!("{flag}: no k given");
    }
    Ok(ks)
}

/// `out` as a relative link from the folder of `readme` (`../results/...` from `docs/`);
/// absolute only where no relative path exists.
fn relative_link(readme: &Path, out: &Path) -> anyhow::Result<String> {
    let out = out.canonicalize().with_context(|| format!("resolving {}", out.display()))?;
    let readme =
        readme.canonicalize().with_context(|| format!("resolving {}", readme.display()))?;
    let base = readme.parent().unwrap_or(Path::new("/"));
    let path = pathdiff::diff_paths(&out, base).unwrap_or(out);
    Ok(path.to_string_lossy().replace('\\', "/"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every generated block of docs/results.md, regenerated from the committed results folder
    /// it links to (its CSV files and summary, nothing retrained), is the block the file holds:
    /// a block left stale by a rerun, an edit of the folder or of the generator fails here.
    #[test]
    fn the_generated_blocks_of_the_docs_match_their_committed_results() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let readme = root.join("docs/results.md");
        let text = std::fs::read_to_string(&readme).unwrap();
        let mut checked = 0;
        for mode in [Mode::KFold { folds: 5 }, Mode::InSample, Mode::Generalize] {
            let (begin, end) = readme_markers(mode);
            let Some(start) = text.find(begin) else { continue };
            let block = &text[start..text.find(end).unwrap()];
            let details = block.lines().find_map(|l| l.strip_prefix("Details: [")).unwrap();
            let folder = details.split_once("/summary.md]").unwrap().0;
            let dir = readme.parent().unwrap().join(folder);
            let saved = SavedSweep::read(&dir).unwrap();
            let (b, e, fresh) = saved_block(&saved, &readme, &dir).unwrap();
            assert_eq!((b, e), (begin, end), "{folder} holds a run of another mode");
            let regenerated = readme_block::replace_block(&text, b, e, &fresh).unwrap();
            assert!(
                regenerated == text,
                "the {begin} block of docs/results.md is stale: run `experiments sweep-k --from \
                 {} --update-readme docs/results.md`",
                folder.trim_start_matches("../")
            );
            checked += 1;
        }
        assert!(checked >= 1, "no generated block in docs/results.md");
    }

    #[test]
    fn results_links_are_relative_to_the_markdown_files_folder() {
        let dir = tempfile::tempdir().unwrap();
        let (docs, results) = (dir.path().join("docs"), dir.path().join("results").join("run"));
        std::fs::create_dir_all(&docs).unwrap();
        std::fs::create_dir_all(&results).unwrap();
        std::fs::write(docs.join("results.md"), "").unwrap();
        std::fs::write(dir.path().join("README.md"), "").unwrap();
        assert_eq!(relative_link(&docs.join("results.md"), &results).unwrap(), "../results/run");
        assert_eq!(relative_link(&dir.path().join("README.md"), &results).unwrap(), "results/run");
    }
}
