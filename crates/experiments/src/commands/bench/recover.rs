//! `experiments bench recover`: seconds of one `recover` (target: network + decode at
//! most 0.5 s on 2 cores): reading and preparing the photo, the recovery CNN, and DeepBRDF's
//! decode of its latent (eq. 3), each the median of `--repeats` runs after a warm-up.
use crate::args::model::ModelArg;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::{Progress, Silent};
use deepbrdf_eval::stats::finite_median;
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::{camera_png, render, MerlBrdf, Photo, RenderSettings, Sampler, SceneConfig};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArg,
    #[command(flatten)]
    pub network: crate::args::network::NetworkArg,
    /// The photo [default: a 256x256 render of gold-metallic-paint on the preview sphere].
    #[arg(long)]
    pub image: Option<PathBuf>,
    #[arg(long, default_value_t = 5)]
    pub repeats: usize,
    #[command(flatten)]
    pub cache: crate::args::data::CacheArg,
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::args::device::device()?;
    let model_dir = args.model.dir()?;
    let model = DeepBrdf::load(&model_dir, &device)?;
    let network = args.network.load(&model_dir, &model)?;
    let predictor = network.predictor(&device)?;
    let dir = tempfile::tempdir()?;
    let image = match &args.image {
        Some(p) => p.clone(),
        None => {
            let (_, table) = load_material("gold-metallic-paint", &args.cache.cache())?;
            let scene = SceneConfig::default().build()?;
            let settings = RenderSettings {
                size: 256,
                spp: 16,
                seed: 0,
                jitter: true,
                sampler: Sampler::Sobol,
            };
            let linear = render(&scene, &MerlBrdf::new(&table), &settings, &Silent)?;
            let path = dir.path().join("photo.png");
            camera_png(&linear, 1.0, 0.0, 0).write_png(&path)?;
            path
        }
    };
    let side = network.config().input_side as u32;
    let (mut prep, mut net, mut dec) = (Vec::new(), Vec::new(), Vec::new());
    for rep in 0..=args.repeats.max(1) {
        let t0 = Instant::now();
        let input = Photo::read(&image)?.network_input(side, &image.display().to_string())?;
        let t1 = Instant::now();
        let latent = predictor.predict(&input)?.remove(0);
        let t2 = Instant::now();
        let table = model.decode(&latent)?;
        let t3 = Instant::now();
        std::hint::black_box(table);
        if rep > 0 {
            prep.push((t1 - t0).as_secs_f64());
            net.push((t2 - t1).as_secs_f64());
            dec.push((t3 - t2).as_secs_f64());
        }
    }
    let (p, n, d) = (finite_median(prep), finite_median(net), finite_median(dec));
    println!(
        "recover {} ({}x{} network input): read + prepare {p:.3} s, network {n:.4} s, decode \
         {d:.3} s; network + decode {:.3} s (target <= 0.5 s), total {:.3} s (medians of {})",
        image.display(),
        side,
        side,
        n + d,
        p + n + d,
        args.repeats.max(1)
    );
    Ok(())
}
