//! `experiments baselines`: the PCA and IPCA baselines of §4 (Hu et al. 2020) and Sun et al.
//! 2018's separation (Fig. 8) through the evaluation harness: fit, encode/decode every material
//! at each k, measure, print the summary table and write the results folder (CSV, markdown,
//! Fig. 3 / Fig. 7 style plots).
use crate::args::data::DataArgs;
use anyhow::{bail, Context};
use deepbrdf_data::bundled::Collection;
use deepbrdf_data::dataset::Dataset;
use deepbrdf_data::Progress;
use deepbrdf_eval::attributes::AttributeMethod;
use deepbrdf_eval::baseline::BaselineMethod;
use deepbrdf_eval::deep::DeepMethod;
use deepbrdf_eval::harness::{self, HarnessConfig, Materials, Measure, Method, Mode};
use deepbrdf_eval::separation::{SeparatedMethod, SeparationConfig};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Files a results folder receives ([`harness::Results::write`]); an earlier run's copies are
/// only replaced with `--force`.
const RESULT_FILES: [&str; 3] = ["results.csv", "fits.csv", "summary.md"];

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Dimensions k of the representation to evaluate (comma-separated).
    #[arg(long = "k", value_name = "K,...", value_delimiter = ',', default_value = "5,10,20,40")]
    pub ks: Vec<usize>,
    /// in-sample (fit on all, evaluate on all: Fig. 3), kfold:N (each material evaluated by a
    /// basis fitted on the other folds), or generalize (fit on the training collection, evaluate
    /// on --eval-collections: Fig. 9).
    #[arg(long, default_value = "in-sample")]
    pub mode: Mode,
    /// Results folder [default: results/baselines-<mode>].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Seed of the k-fold split.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// kfold mode: score only this fold's held-out materials (one training; `experiments folds
    /// --fold F` lists them).
    #[arg(long, value_name = "F")]
    pub fold: Option<usize>,
    /// Measures (comma-separated): mapped_mse (eq. 1 space), cos_rmse, image_relae (renders
    /// the original and each reconstruction: ~0.3 s of CPU per pair), and the highlight's
    /// defects, counted: dark_hole (a dark dot at its centre), tinted_centre (its colour moved).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "mapped_mse,cos_rmse,dark_hole,tinted_centre"
    )]
    pub measures: Vec<Measure>,
    /// Methods (comma-separated): pca, ipca, sun2018 (Sun et al. 2018's diffuse-specular
    /// separation, Fig. 8: 1 diffuse + k - 1 specular coefficients), ggx (the 7-number
    /// Lambertian + GGX attribute fit, `deepbrdf_eval::attributes`; needs --k 7), deepbrdf
    /// (trained with --preset into --models, or loaded from there when finished).
    #[arg(long, value_name = "NAME,...", value_delimiter = ',', default_value = "pca,ipca")]
    pub methods: Vec<String>,
    /// Train every method on these bundled collections too, in every fold, and never score
    /// them (comma-separated; named `COLLECTION/NAME`), e.g. `--mode kfold:5
    /// --add-collections nielsen2015,rgl,rgl-measured`.
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub add_collections: Vec<Collection>,
    /// The sun2018 method's diffuse coefficients (1, Fig. 8's setting; 3 keeps each albedo as
    /// the separation found it, at k + 2 numbers per material in all).
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub sun_diffuse_dims: usize,
    /// The sun2018 method's eps in the mapping of the specular part (IPCA's 0.001 by default).
    #[arg(long, value_name = "EPS", default_value_t = deepbrdf_eval::ipca::EPSILON)]
    pub sun_specular_epsilon: f64,
    /// The preset of the deepbrdf method.
    #[arg(long, default_value = "slice")]
    pub preset: deepbrdf_model::Preset,
    /// A training configuration of the deepbrdf method (JSON, as `train` saves it, e.g.
    /// `configs/table1-cpu.json`) instead of --preset; its k is set to each --k.
    #[arg(long, value_name = "FILE", conflicts_with = "preset")]
    pub config: Option<PathBuf>,
    #[command(flatten)]
    pub refine: crate::args::refine::RefineArg,
    /// The deepbrdf method stops each training at the end of the first epoch past this many
    /// seconds and is evaluated as far as it got (a rerun resumes the training).
    #[arg(long, value_name = "SECONDS", value_parser = crate::args::time_limit::parse)]
    pub time_limit: Option<std::time::Duration>,
    /// Where the deepbrdf method trains its models (`fold<F>/k<K>`) [default: <out>/models].
    #[arg(long, value_name = "DIR")]
    pub models: Option<PathBuf>,
    /// Generalize mode: the bundled collections to evaluate on (comma-separated).
    #[arg(long, value_name = "NAME,...", value_delimiter = ',', default_value = "nielsen2015,rgl")]
    pub eval_collections: Vec<Collection>,
    /// Also write the fitted bases (PCA.basis, IPCA.basis, largest k) into DIR
    /// (in-sample and generalize modes, where one basis is fitted on all training materials).
    #[arg(long, value_name = "DIR")]
    pub save_basis: Option<PathBuf>,
    /// Replace the result (and basis) files of an earlier run; other files are never touched.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub data: DataArgs,
}

/// The default results folder of a mode: `results/baselines-in-sample`, `-kfold-5`, ...
pub fn default_out(mode: Mode) -> PathBuf {
    PathBuf::from("results").join(format!("baselines-{}", mode.to_string().replace(':', "-")))
}

impl Args {
    /// The harness's settings: ks, mode, seed, measures and the one fold asked for.
    fn harness_config(&self) -> anyhow::Result<HarnessConfig> {
        let config = HarnessConfig {
            ks: self.ks.clone(),
            mode: self.mode,
            seed: self.seed,
            measures: self.measures.clone(),
            only_fold: self.fold,
        };
        config.validate()?;
        Ok(config)
    }

    /// Sun et al. 2018's split with the asked diffuse dimensions and specular epsilon.
    fn sun_method(&self) -> SeparatedMethod {
        SeparatedMethod::new(SeparationConfig {
            diffuse_dims: self.sun_diffuse_dims,
            specular_epsilon: self.sun_specular_epsilon,
            ..SeparationConfig::default()
        })
    }
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let started = Instant::now();
    let config = args.harness_config()?;
    check(&args)?;
    let out = args.out.clone().unwrap_or_else(|| default_out(args.mode));
    // Held until the run ends: a second run on the same folder is refused.
    let _lock = deepbrdf_data::lock::FolderLock::acquire(&out)?;
    // Refuse before any work, so a long run never ends by refusing to write.
    check_not_overwriting(&out, &RESULT_FILES, args.force, "results of an earlier run")?;
    let (pca, ipca) = linear_methods(&args)?;
    let (train, added, eval) = load(&args, progress)?;
    let train_label = format!("{} ({} materials)", train.label, train.len());
    let added_label =
        added.as_ref().map(|a| format!("{} ({} materials)", a.label, a.len())).unwrap_or_default();
    let data_label = match &added {
        Some(a) => format!("{}+{}", train.label, a.label),
        None => train.label.clone(),
    };
    let eval_label = eval.as_ref().map(|e| format!("{} ({} materials)", e.label, e.len()));
    let ggx = AttributeMethod::default();
    let sun = args.sun_method();
    let deep = deep_method(&args, &out, &data_label)?;
    let methods: Vec<&dyn Method> = args
        .methods
        .iter()
        .map(|m| match m.as_str() {
            "pca" => &pca as &dyn Method,
            "ipca" => &ipca,
            "deepbrdf" => &deep,
            "sun2018" => &sun,
            _ => &ggx,
        })
        .collect();
    let results = harness::run_with_extra(
        &methods,
        &config,
        Materials { names: &train.names, tables: &train.tables, label: &train_label },
        added.as_ref().map(|a| Materials {
            names: &a.names,
            tables: &a.tables,
            label: &added_label,
        }),
        eval.as_ref().zip(eval_label.as_deref()).map(|(e, label)| Materials {
            names: &e.names,
            tables: &e.tables,
            label,
        }),
        progress,
    )?;
    results.write(&out).with_context(|| format!("writing the results to {}", out.display()))?;
    if let Some(dir) = &args.save_basis {
        let kept: Vec<&BaselineMethod> = [("pca", &pca), ("ipca", &ipca)]
            .into_iter()
            .filter(|(name, _)| args.methods.iter().any(|m| m == name))
            .map(|(_, m)| m)
            .collect();
        save_bases(dir, &kept)?;
    }
    print_results(&results, &out, started);
    Ok(())
}

/// What the run measured, its times and where the results are.
fn print_results(results: &harness::Results, out: &Path, started: Instant) {
    println!(
        "{} mode: trained on {}, evaluated on {}\n",
        results.mode, results.train_label, results.eval_label
    );
    println!("{}", results.summary_table());
    let fit_seconds: f64 = results.fits.iter().map(|f| f.seconds).sum();
    println!(
        "fits {:.1} s, encoding + decoding + measuring {:.1} s, whole command {:.1} s",
        fit_seconds,
        results.eval_seconds,
        started.elapsed().as_secs_f64()
    );
    println!("results written to {}", out.display());
}

/// PCA and IPCA, keeping their last fit where `--save-basis` asks (refused before any work
/// where that would overwrite a saved basis).
fn linear_methods(args: &Args) -> anyhow::Result<(BaselineMethod, BaselineMethod)> {
    let (pca, ipca) = (BaselineMethod::pca(), BaselineMethod::ipca());
    let Some(dir) = &args.save_basis else { return Ok((pca, ipca)) };
    let names = [format!("{}.basis", pca.name()), format!("{}.basis", ipca.name())];
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    check_not_overwriting(dir, &names, args.force, "a saved basis")?;
    Ok((pca.keeping_last_fit(), ipca.keeping_last_fit()))
}

/// DeepBRDF trained with the preset (or the configuration file) for each k (its models under
/// `--models`, else `out/models`), encoding with the refinement asked.
fn deep_method(args: &Args, out: &Path, data_label: &str) -> anyhow::Result<DeepMethod> {
    let preset = args.preset;
    let file = args.config.as_deref().map(deepbrdf_model::TrainConfig::from_file).transpose()?;
    let config_for = move |k| match &file {
        Some(config) => {
            let mut config = config.clone();
            config.model.latent = k;
            config
        }
        None => preset.train_config(k),
    };
    let models = args.models.clone().unwrap_or_else(|| out.join("models"));
    Ok(DeepMethod::new(Box::new(config_for), &models, data_label, crate::args::device::device()?)
        .retaining(&[])
        .refining(args.refine.refinement()?)
        .training_within(args.time_limit))
}

/// Refuses option combinations that cannot run, before any work.
fn check(args: &Args) -> anyhow::Result<()> {
    if args.save_basis.is_some() && matches!(args.mode, Mode::KFold { .. }) {
        bail!("--save-basis needs in-sample or generalize mode (k-fold fits one basis per fold)");
    }
    if args.mode != Mode::Generalize && args.eval_collections != default_eval_collections() {
        bail!("--eval-collections is for generalize mode only");
    }
    for m in &args.methods {
        if !["pca", "ipca", "sun2018", "ggx", "deepbrdf"].contains(&m.as_str()) {
            bail!("unknown method '{m}' (pca, ipca, sun2018, ggx, deepbrdf)");
        }
    }
    if args.methods.iter().any(|m| m == "ggx") && args.ks != [7] {
        bail!("the ggx method has exactly 7 parameters: run it with --k 7");
    }
    Ok(())
}

/// The training set, the collections added to training, and (generalize mode) the evaluation
/// set, each load's time printed.
fn load(
    args: &Args,
    progress: &dyn Progress,
) -> anyhow::Result<(Dataset, Option<Dataset>, Option<Dataset>)> {
    let loaded = |set: &Dataset, t: Instant| {
        let secs = t.elapsed().as_secs_f64();
        eprintln!("loaded {} ({} materials) in {secs:.1} s", set.label, set.len());
    };
    let t = Instant::now();
    let train = args.data.load(progress)?;
    loaded(&train, t);
    let eval = if args.mode == Mode::Generalize {
        let t = Instant::now();
        let eval =
            crate::args::data::load_collections(&args.eval_collections, &args.data, progress)?;
        loaded(&eval, t);
        Some(eval)
    } else {
        None
    };
    let added = (!args.add_collections.is_empty())
        .then(|| crate::args::data::load_added(&args.add_collections, &args.data.cache(), progress))
        .transpose()?;
    Ok((train, added, eval))
}

fn default_eval_collections() -> Vec<Collection> {
    vec![Collection::Nielsen2015, Collection::Rgl]
}

/// Fails when `dir` already holds one of `files`, unless `force`.
fn check_not_overwriting(
    dir: &Path,
    files: &[&str],
    force: bool,
    what: &str,
) -> anyhow::Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("{} exists and is not a directory", dir.display());
    }
    if force {
        return Ok(());
    }
    if let Some(f) = files.iter().find(|f| dir.join(f).exists()) {
        bail!(
            "{} already holds {what} ({f}); pass --force to replace those files (nothing else \
             in the folder is touched) or choose another folder",
            dir.display()
        );
    }
    Ok(())
}

/// Writes each method's kept basis to `dir/<name>.basis`.
fn save_bases(dir: &Path, methods: &[&BaselineMethod]) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    for m in methods {
        let basis =
            m.last_fit().with_context(|| format!("{} kept no fitted basis to save", m.name()))?;
        let path = dir.join(format!("{}.basis", basis.name()));
        basis.save(&path)?;
        println!(
            "saved {} basis ({} components, {} training materials) to {}",
            basis.name(),
            basis.basis().k(),
            basis.n_train(),
            path.display()
        );
    }
    Ok(())
}
