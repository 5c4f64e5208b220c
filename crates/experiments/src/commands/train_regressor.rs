//! `experiments train-regressor [--model DIR] [--collection NAME | --data DIR] [--out DIR]
//! [--ipca]`: trains the attribute-to-latent regressor of §5.1 (eq. (7), Fig. 11) for a DeepBRDF
//! model: the 7 attributes of each material (the Lambertian + GGX fit,
//! `deepbrdf_eval::attributes`) to its latent values under the model (eq. 2), through the shared
//! training loop; saved as `<out>/deepbrdf.regressor` (default out: `<model>/regressor/`), naming
//! the model. With `--ipca`, also an IPCA basis at the same k (`ipca.basis`) and the regressor of
//! its coefficients (`ipca.regressor`), for the paper's Fig. 14 comparison.
use crate::args::data::DataArgs;
use crate::args::model::ModelArg;
use crate::editing::{self, config, ipca_owner_id, train_into, IPCA_BASIS_FILE};
use anyhow::{bail, Context};
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::attributes::FitConfig;
use deepbrdf_eval::baseline::{BaselineBasis, MappingKind};
use deepbrdf_model::regressor::{RegressorData, Target, TargetKind};
use deepbrdf_model::DeepBrdf;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArg,
    /// Output folder [default: <model>/regressor].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also fit IPCA at the model's k on the same materials and train a regressor of its
    /// coefficients.
    #[arg(long)]
    pub ipca: bool,
    /// Epochs [default: the library's, 3000].
    #[arg(long)]
    pub epochs: Option<usize>,
    /// Seed of the initialisation and the batch order.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Replace regressors already in the output folder.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub data: DataArgs,
    #[command(flatten)]
    pub corpus: crate::args::corpus::CorpusArg,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let started = Instant::now();
    let model_dir = args.model.dir()?;
    let out = prepare_out(&args, &model_dir)?;
    let device = crate::args::device::device()?;
    let set = args.data.load(progress)?;
    let streamed = args.corpus.streamed()?;
    let model = DeepBrdf::load(&model_dir, &device)
        .with_context(|| format!("loading the model {}", model_dir.display()))?;
    let k = model.k();
    // IPCA's basis is fitted to the held tables (a streamed corpus is not held); every
    // material, streamed ones included, gets its coefficients in it as a regression target.
    let ipca = match args.ipca {
        true => {
            let refs: Vec<_> = set.tables.iter().collect();
            let basis = BaselineBasis::fit("IPCA", MappingKind::LogRelative, &refs, k, progress)?;
            basis.save(&out.join(IPCA_BASIS_FILE))?;
            Some(basis)
        }
        false => None,
    };
    let mut gathered = Gathered::new(&model, ipca.as_ref());
    progress.start(set.len() as u64, "attributes and latents");
    for (name, table) in set.names.iter().zip(&set.tables) {
        gathered.add(name, table)?;
        progress.advance(1);
    }
    progress.finish();
    let mut label = set.label.clone();
    if let Some(streamed) = &streamed {
        progress.start(streamed.len() as u64, "attributes and latents of the streamed corpus");
        let mut failed = None;
        let streamed_result = streamed.for_each(progress, |_, name, table| {
            gathered.add(name, &table).map_err(|e| {
                failed = Some(e);
                deepbrdf_model::ModelError::Invalid("stopped".into())
            })
        });
        if let Some(e) = failed {
            return Err(e);
        }
        streamed_result?;
        progress.finish();
        label = format!("{label}+{}", streamed.label());
    }
    let Gathered { names, attributes, latents, coefficients, .. } = gathered;
    let config = config(args.epochs, args.seed);
    let data = RegressorData { label, names, attributes, targets: latents };
    let target = Target { kind: TargetKind::DeepBrdf, owner_id: model.id().to_string(), k };
    train_into(&out, &data, &config, target, progress, &device)?;
    if let Some(basis) = ipca {
        drop(model);
        let data = RegressorData { targets: coefficients, ..data };
        let target = Target { kind: TargetKind::Ipca, owner_id: ipca_owner_id(&basis, k), k };
        train_into(&out, &data, &config, target, progress, &device)?;
    }
    println!("whole command {:.1} s", started.elapsed().as_secs_f64());
    Ok(())
}

/// The output folder, checked (an existing regressor is replaced only with `--force`, which
/// also removes the old training runs) and created.
fn prepare_out(args: &Args, model_dir: &Path) -> anyhow::Result<PathBuf> {
    let out = args.out.clone().unwrap_or_else(|| editing::regressor_dir(model_dir, None));
    for kind in [TargetKind::DeepBrdf, TargetKind::Ipca] {
        let path = out.join(kind.file_name());
        if path.exists() && !args.force && (kind == TargetKind::DeepBrdf || args.ipca) {
            bail!("{} exists; pass --force to replace it", path.display());
        }
    }
    if args.force && out.join("runs").exists() {
        std::fs::remove_dir_all(out.join("runs"))
            .with_context(|| format!("removing the old runs in {}", out.display()))?;
    }
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    Ok(out)
}

/// The regression data gathered material by material: each one's fitted attributes (the
/// inputs), its latent under the model and, where IPCA is trained too, its IPCA coefficients
/// (the targets).
struct Gathered<'a> {
    model: &'a DeepBrdf,
    ipca: Option<&'a BaselineBasis>,
    fit: FitConfig,
    names: Vec<String>,
    attributes: Vec<[f64; 7]>,
    latents: Vec<Vec<f32>>,
    coefficients: Vec<Vec<f32>>,
}

impl<'a> Gathered<'a> {
    fn new(model: &'a DeepBrdf, ipca: Option<&'a BaselineBasis>) -> Self {
        let fit = FitConfig::default();
        let (names, attributes, latents, coefficients) = (vec![], vec![], vec![], vec![]);
        Self { model, ipca, fit, names, attributes, latents, coefficients }
    }

    fn add(&mut self, name: &str, table: &MerlTable) -> anyhow::Result<()> {
        self.attributes.push(editing::attributes_of(table, name, &self.fit)?.to_array());
        let latent = self.model.encode(table).with_context(|| format!("encoding {name}"))?;
        self.latents.push(latent);
        if let Some(basis) = self.ipca {
            self.coefficients.push(basis.encode(table, self.model.k())?);
        }
        self.names.push(name.to_string());
        Ok(())
    }
}
