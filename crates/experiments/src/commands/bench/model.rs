//! `experiments bench model`: training seconds per BRDF for the presets (and their ratio), and
//! the time to decode a latent vector into a full MERL table next to IPCA's decode of k
//! coefficients (targets: DeepBRDF at most 1.0 x IPCA and at most 0.15 s on 2 cores;
//! the paper reports 0.3 s for DeepBRDF on a GPU and 0.15 s for IPCA, 2.0 x). All measured in
//! the same run, the networks on the `--device` backend.
use deepbrdf_data::testing::synthetic_set;
use deepbrdf_data::{MerlTable, Progress, Silent};
use deepbrdf_eval::baseline::{BaselineBasis, MappingKind};
use deepbrdf_model::autoencoder::ConvAlgorithm;
use deepbrdf_model::timing::{self, Timing};
use deepbrdf_model::{Preset, TrainConfig};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Which preset to time: paper or slice (default: both).
    #[arg(long, value_name = "NAME", value_parser = parse_preset)]
    pub preset: Option<Preset>,
    /// Latent dimension k.
    #[arg(long, default_value_t = 10)]
    pub k: usize,
    /// BRDFs per training batch, one row each (comma-separated) [default: each preset's own
    /// batch size].
    #[arg(long, value_delimiter = ',')]
    pub batch: Vec<usize>,
    /// Timed training steps per preset (after one warm-up step).
    #[arg(long, default_value_t = 3)]
    pub steps: usize,
    /// Timed decodes per preset (after one warm-up).
    #[arg(long, default_value_t = 5)]
    pub decodes: usize,
    /// How the convolutional network computes its convolutions: gemm, direct, or both, one row
    /// each (comma-separated) [default: the configuration's, gemm].
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub conv: Vec<ConvAlgorithm>,
    /// Rewrite the decode block of this markdown file (the README's, between
    /// `<!-- bench-decode:begin -->` and `<!-- bench-decode:end -->`) from this run: the
    /// `slice` preset's decode beside IPCA's.
    #[arg(long, value_name = "FILE")]
    pub update_readme: Option<std::path::PathBuf>,
    /// Also time the network of this training configuration (JSON, as `train` saves it).
    #[arg(long, value_name = "FILE")]
    pub config: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub torch: super::torch::TorchArgs,
}

fn parse_preset(s: &str) -> Result<Preset, String> {
    s.parse()
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let kind = crate::args::device::kind()?;
    let device = crate::args::device::device()?;
    let runs = networks(&args)?;
    println!("device {kind}, k = {}", args.k);
    let ipca = ipca_decode(args.k, args.decodes)?;
    println!(
        "{:12} {:>6} {:>16} {:>16} {:>14} {:>14}",
        "preset", "batch", "train s/step", "train s/sample", "decode net s", "decode all s"
    );
    let mut per_sample = Vec::new();
    let mut slice_decode = None;
    let mut table1 = Vec::new();
    for (name, config) in runs {
        let batches =
            if args.batch.is_empty() { vec![config.batch_size] } else { args.batch.clone() };
        let steps = batches
            .iter()
            .map(|&batch| {
                let train = timing::training_steps(
                    &config.model,
                    batch,
                    config.threads,
                    args.steps,
                    &device,
                )?;
                Ok((batch, train.median()))
            })
            .collect::<anyhow::Result<Vec<(usize, f64)>>>()?;
        let decode = timing::decode(&config.model, args.decodes, &device)?;
        let (net, all) = (&decode.network, &decode.whole);
        for (i, &(batch, step)) in steps.iter().enumerate() {
            print!("{:12} {:>6} {:>16.3} {:>16.4}", name, batch, step, step / batch as f64);
            match i + 1 == steps.len() {
                true => println!(" {:>14.4} {:>14.4}", net.median(), all.median()),
                false => println!(),
            }
            if config.model.slice_config().is_none() {
                table1.push((name.clone(), batch, step / batch as f64));
            }
        }
        let (batch, step) = steps[steps.len() - 1];
        let (deep, linear) = (all.median(), ipca.median());
        let ratio = deep / linear;
        println!(
            "{:12} decode vs IPCA's at k = {}: {deep:.4} s vs {linear:.4} s ({ratio:.2}x, same run)",
            "", args.k
        );
        if name == Preset::Slice.name() {
            slice_decode = Some(all.median());
        }
        per_sample.push((name, step / batch as f64));
    }
    super::torch::compare(&args.torch, &table1, args.steps)?;
    if let [(a, ta), (b, tb)] = &per_sample[..] {
        println!("training cost per sample: {b} / {a} = {:.1}x", tb / ta);
    }
    print_conv_ratios(&per_sample);
    println!("(medians; decode = network + inverse layout + inverse eq. (1) to a full MERL table)");
    println!(
        "IPCA decode at k = {}: {:.4} s (k coefficients -> the basis' row -> the inverse \
         cosine-weighted log-relative mapping -> a full MERL table)",
        args.k,
        ipca.median()
    );
    if let (Some(readme), Some(deep)) = (&args.update_readme, slice_decode) {
        let block = decode_block(args.k, deep, ipca.median(), &args);
        crate::readme_block::update_file(readme, DECODE_BEGIN, DECODE_END, &block)?;
        println!("wrote the decode block of {}", readme.display());
    }
    Ok(())
}

/// The networks timed: the preset asked (or every preset), the configuration file asked, each
/// with every convolution algorithm asked; refused where `--update-readme` has no slice
/// network to time.
fn networks(args: &Args) -> anyhow::Result<Vec<(String, TrainConfig)>> {
    let mut runs: Vec<(String, TrainConfig)> = match (args.preset, &args.config) {
        (Some(p), _) => vec![(p.name().to_string(), p.train_config(args.k))],
        (None, Some(_)) => Vec::new(),
        (None, None) => {
            Preset::ALL.iter().map(|p| (p.name().to_string(), p.train_config(args.k))).collect()
        }
    };
    if let Some(path) = &args.config {
        let config = TrainConfig::from_file(path)?;
        runs.push(("config".to_string(), config));
    }
    if !args.conv.is_empty() {
        runs = with_conv(runs, &args.conv)?;
    }
    if args.update_readme.is_some() && !runs.iter().any(|(name, _)| name == Preset::Slice.name()) {
        anyhow::bail!(
            "--update-readme writes the slice preset's decode time: run with --preset slice"
        );
    }
    Ok(runs)
}

/// Marker lines of the block `--update-readme` writes.
const DECODE_BEGIN: &str = "<!-- bench-decode:begin -->";
const DECODE_END: &str = "<!-- bench-decode:end -->";

/// The README's decode row, from one run: the `slice` preset's decode beside IPCA's at `k`,
/// the paper's claim, and the command that wrote it.
fn decode_block(k: usize, deep: f64, ipca: f64, args: &Args) -> String {
    let threads = rayon::current_num_threads();
    format!(
        "| Decoding one full table, k = {k} | the paper's claim | measured here: DeepBRDF \
         (`slice`) / IPCA | command |\n| --- | --- | --- | --- |\n| latent or coefficients to \
         a full MERL table | DeepBRDF 0.3 s, IPCA 0.15 s (a GPU; 2.0x) | {deep:.3} s / \
         {ipca:.3} s (**{ratio:.2}x**; medians of {decodes}, {threads} threads, one run) | \
         `RAYON_NUM_THREADS={threads} experiments bench model --preset slice --k {k} --steps \
         {steps} --decodes {decodes} --update-readme README.md` |\n",
        ratio = deep / ipca,
        decodes = args.decodes,
        steps = args.steps,
    )
}

/// `NAME training step: direct / gemm = X` for each run timed both ways (`--conv direct,gemm`).
fn print_conv_ratios(per_sample: &[(String, f64)]) {
    for (name, step) in per_sample {
        let Some(base) = name.strip_suffix("/gemm") else { continue };
        if let Some((_, direct)) = per_sample.iter().find(|(n, _)| *n == format!("{base}/direct")) {
            println!("{base} training step: direct / gemm = {:.2}x (same run)", direct / step);
        }
    }
}

/// Each convolutional run once per algorithm of `conv`, named `NAME/ALGORITHM`; the others
/// (the slice network has no convolutions) once.
fn with_conv(
    runs: Vec<(String, TrainConfig)>,
    conv: &[ConvAlgorithm],
) -> anyhow::Result<Vec<(String, TrainConfig)>> {
    let mut out = Vec::new();
    for (name, config) in runs {
        if config.model.slice_config().is_some() {
            out.push((name, config));
            continue;
        }
        for &algorithm in conv {
            let mut config = config.clone();
            config.model.set_conv(algorithm)?;
            out.push((format!("{name}/{algorithm}"), config));
        }
    }
    Ok(out)
}

/// Times IPCA's decode of `k` coefficients into a full MERL table (`repeats` runs after a
/// warm-up), with a basis fitted to `k + 2` tables of the synthetic family: its speed depends
/// on k and the grid's valid cells, not on which materials were fitted.
fn ipca_decode(k: usize, repeats: usize) -> anyhow::Result<Timing> {
    let (_, tables) = synthetic_set(k + 2);
    let refs: Vec<&MerlTable> = tables.iter().collect();
    let basis = BaselineBasis::fit("IPCA", MappingKind::LogRelative, &refs, k, &Silent)?;
    let code = basis.encode(&tables[0], k)?;
    Ok(timing::timed(repeats, || basis.decode(&code))?)
}
