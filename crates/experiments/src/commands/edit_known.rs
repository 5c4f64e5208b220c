//! `experiments edit-known [--model DIR] [--count N] [--seed S] [--out DIR]`: edits measured
//! against a known answer. Analytic corpus materials
//! (`deepbrdf_data::corpus`, drawn with a seed no network was trained on) are edited as a user
//! would: their 7 attributes fitted, then roughness x0.5 and x2, diffuse and specular albedo x0.5
//! and a recolour (the diffuse channels rotated) asked of the fit. The answer is the same
//! material with the parameter changed. Each edit is made by each method asked for (the edits
//! without a network, DeepBRDF's and IPCA's at the model's k) and scored by image RelAE against
//! the answer's render next to the unedited material's (`deepbrdf_eval::editing::known::suite`).
//!
//! Writes `results.md` (the tally per method and edit) and `known.csv` (every edit).
use crate::args::data::DataArgs;
use crate::editing::{self, EditorArg, ModelCodec, Space};
use anyhow::Context;
use deepbrdf_data::Progress;
use deepbrdf_eval::attributes::FitConfig;
use deepbrdf_eval::editing::known;
use deepbrdf_eval::editing::known::suite::{self as known_suite, KnownInput, KnownMethod};
use deepbrdf_eval::separation;
use std::path::PathBuf;
use std::time::Instant;

/// The seed of the known-answer materials by default: not the training corpus' seed.
pub const DEFAULT_SEED: u64 = 0x6b6e_6f77_6e;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub editor: EditorArg,
    /// Number of corpus materials (the sampler draws each one's family at random).
    #[arg(long, default_value_t = 21, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub count: u64,
    /// Seed of the corpus materials.
    #[arg(long, default_value_t = DEFAULT_SEED)]
    pub seed: u64,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "runs/edit-known")]
    pub out: PathBuf,
    /// The methods that edit (comma-separated): analytic, stretch (no network),
    /// deepbrdf-residual, deepbrdf-paper, deepbrdf-transfer, deepbrdf-transfer-paper,
    /// ipca-residual, ipca-transfer, sun2018-stretch (the stretch edit on Sun et al. 2018's
    /// split, fitted to the data below).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "analytic,deepbrdf-residual,deepbrdf-paper,ipca-residual"
    )]
    pub methods: Vec<KnownMethod>,
    /// Epochs of the IPCA regressor when none is saved [default: the library's].
    #[arg(long)]
    pub epochs: Option<usize>,
    /// The materials IPCA and Sun et al. 2018's separation are fitted to (and IPCA's regressor
    /// trained on, when none is saved).
    #[command(flatten)]
    pub data: DataArgs,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let started = Instant::now();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let device = crate::args::device::device()?;
    let (model_dir, model, deep_regressor) = args.editor.load(&device)?;
    let k = model.k();
    let wants = |f: fn(KnownMethod) -> bool| args.methods.iter().any(|&m| f(m));
    let sun = |m: KnownMethod| m == KnownMethod::Sun2018Stretch;
    // The training materials, for IPCA and the separation when either is asked for.
    let set = match wants(KnownMethod::ipca) || wants(sun) {
        true => Some(args.data.load(progress)?),
        false => None,
    };
    let separation = match set.as_ref().filter(|_| wants(sun)) {
        Some(set) => Some(separation::fit_split(&set.tables.iter().collect::<Vec<_>>(), progress)?),
        None => None,
    };
    // IPCA at the model's k on the training materials, with its regressor, when asked for.
    let ipca = match set.as_ref().filter(|_| wants(KnownMethod::ipca)) {
        Some(set) => {
            let attrs = editing::attributes_of_all(set, &FitConfig::default(), progress)?;
            let reg_dir = editing::regressor_dir(&model_dir, args.editor.regressor.as_deref());
            let scratch = args.out.join("ipca-regressor");
            let epochs = args.epochs;
            Some(editing::ipca_editor(
                &reg_dir, set, &attrs, k, epochs, &scratch, progress, &device,
            )?)
        }
        None => None,
    };
    let deep_codec = ModelCodec(&model);
    let input = KnownInput {
        count: args.count,
        seed: args.seed,
        methods: &args.methods,
        deepbrdf: Some(Space { codec: &deep_codec, regressor: &deep_regressor }),
        ipca: ipca.as_ref().map(|(codec, regressor)| Space { codec, regressor }),
        separation: separation.as_ref(),
    };
    let result = known_suite::run(&input, progress)?;
    let (rows, skipped) = (&result.rows, result.skipped);
    let summary = known::markdown(rows);
    let md = results_md(&args, &model.id(), k, &summary, skipped);
    deepbrdf_data::files::write_atomic(&args.out.join("results.md"), md.as_bytes())?;
    deepbrdf_data::files::write_atomic(&args.out.join("known.csv"), known::csv(rows).as_bytes())?;
    println!("{summary}");
    println!(
        "{} edits of {} materials ({skipped} skipped) in {:.0} s -> {}",
        rows.len() / args.methods.len().max(1),
        args.count,
        started.elapsed().as_secs_f64(),
        args.out.display()
    );
    Ok(())
}

/// The results' text: how they were made, then the summary table.
fn results_md(args: &Args, model: &str, k: usize, summary: &str, skipped: usize) -> String {
    format!(
        "# Edits against known answers\n\nWritten by `experiments edit-known --count {} --seed {}` \
         (model {}, k = {k}; IPCA, where run, at k = {k} fitted to {}; {} analytic corpus materials, none of \
         them seen by any network; {} edits skipped where the answer is not the edit asked: an \
         albedo the material lacks, a roughness clamped). Distance: image RelAE against the \
         answer's render (128 px sphere, sun and sky, 16 spp); ratio = edited / unedited \
         distance; the bar: at most 0.5 on >= 90% of edits and never above 1. Dark holes: \
         edits that left a value at theta_h ~ 0 below 60% of the lobe's maximum within 15 deg \
         where the original had none (`deepbrdf_eval::editing::lobe`).\n\n{summary}",
        args.count,
        args.seed,
        model,
        args.data.source().label(),
        args.count,
        skipped
    )
}
