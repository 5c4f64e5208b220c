//! `experiments bench layers`: the per-layer profile of Table 1's network (forward, input
//! gradient and weight gradient of each layer, seconds and GFLOP/s) beside the rate of one
//! large matrix product measured in the same run.
use deepbrdf_data::Progress;
use deepbrdf_model::autoencoder::convolutional::profile::{matmul_gflops, profile, LayerTiming};
use deepbrdf_model::autoencoder::ConvAlgorithm;
use deepbrdf_model::Preset;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// BRDFs per batch.
    #[arg(long, default_value_t = 4)]
    pub batch: usize,
    /// Timed runs of each pass (medians; after one warm-up).
    #[arg(long, default_value_t = 3)]
    pub repeats: usize,
    /// Latent dimension k.
    #[arg(long, default_value_t = 10)]
    pub k: usize,
    /// How the convolutions are computed: gemm or direct [default: the preset's, gemm].
    #[arg(long, value_name = "ALGORITHM")]
    pub conv: Option<ConvAlgorithm>,
    /// Side of the square matrix product timed as the ceiling.
    #[arg(long, default_value_t = 2048)]
    pub matmul: usize,
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::args::device::device()?;
    let mut config = Preset::Paper.train_config(args.k).model;
    if let Some(conv) = args.conv {
        config.set_conv(conv)?;
    }
    let ceiling = matmul_gflops(args.matmul, args.repeats, &device)?;
    println!(
        "device {}, {} threads, Table 1 (paper preset), batch {}, medians of {}",
        crate::args::device::kind()?,
        rayon::current_num_threads(),
        args.batch,
        args.repeats
    );
    println!("one {0}x{0} f32 matrix product: {ceiling:.1} GFLOP/s (same run)", args.matmul);
    let layers = profile(&config, args.batch, args.repeats, &device)?;
    print_table(&layers, ceiling);
    Ok(())
}

fn print_table(layers: &[LayerTiming], ceiling: f64) {
    println!(
        "{:8} {:>14} {:>14} {:>8} {:>9} {:>9} {:>9} {:>7} {:>7} {:>7} {:>6}",
        "layer", "in", "out", "GMAC", "fwd s", "dx s", "dw s", "fwd GF", "dx GF", "dw GF", "share"
    );
    let total: f64 = layers.iter().map(LayerTiming::total).sum();
    let shape = |s: &[usize]| s.iter().map(|d| d.to_string()).collect::<Vec<_>>().join("x");
    for l in layers {
        println!(
            "{:8} {:>14} {:>14} {:>8.2} {:>9.4} {:>9.4} {:>9.4} {:>7.1} {:>7.1} {:>7.1} {:>5.1}%",
            l.name,
            shape(&l.input),
            shape(&l.output),
            l.macs / 1e9,
            l.forward,
            l.input_gradient,
            l.weight_gradient,
            l.gflops(l.forward),
            l.gflops(l.input_gradient),
            l.gflops(l.weight_gradient),
            100.0 * l.total() / total
        );
    }
    let macs: f64 = layers.iter().map(|l| 3.0 * l.macs).sum();
    println!(
        "all layers: {total:.3} s, {:.1} GMAC, {:.1} GFLOP/s ({:.0}% of the matrix product's rate)",
        macs / 1e9,
        2.0 * macs / total / 1e9,
        100.0 * 2.0 * macs / total / 1e9 / ceiling
    );
}
