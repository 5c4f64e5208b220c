//! `experiments recover [--model DIR] IMAGE -o out.binary [--render compare.png]`: single-image
//! BRDF recovery (§5.2, Fig. 15): the recovery CNN maps the photo to the model's latent vector
//! and the model's decoder (eq. 3) turns it into a full MERL table.
use crate::args::model::ModelArg;
use crate::args::network::NetworkArg;
use deepbrdf_data::merl::write_merl;
use deepbrdf_data::Progress;
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::photo::input_preview;
use deepbrdf_render::{
    render, MerlBrdf, Photo, RenderSettings, Sampler, SceneConfig, Srgb8Image, Tonemap,
};
use std::path::PathBuf;
use std::time::Instant;

/// The arguments of `recover` (its assumptions about the photo: the command's help in `cli.rs`).
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArg,
    #[command(flatten)]
    pub network: NetworkArg,
    /// The photo: PNG, JPEG or EXR.
    pub image: PathBuf,
    /// The recovered MERL .binary file to write.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Also write the input as the network sees it beside a render of the recovered material
    /// (a sphere under the default sun and sky).
    #[arg(long, value_name = "PNG")]
    pub render: Option<PathBuf>,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::args::device::device()?;
    let model_dir = args.model.dir()?;
    let model = DeepBrdf::load(&model_dir, &device)?;
    let network = args.network.load(&model_dir, &model)?;
    let photo = Photo::read(&args.image)?;
    let side = network.config().input_side;
    let what = args.image.display().to_string();
    let input = photo.network_input(side as u32, &what)?;
    let start = Instant::now();
    let latent = network.predictor(&device)?.predict(&input)?.remove(0);
    let table = model.decode(&latent)?;
    let seconds = start.elapsed().as_secs_f64();
    write_merl(&table, &args.output)?;
    let text: Vec<String> = latent.iter().map(|v| format!("{v:.4}")).collect();
    println!(
        "{}: latent [{}] (network + decode {seconds:.2} s) -> {}",
        args.image.display(),
        text.join(" "),
        args.output.display()
    );
    if let Some(path) = &args.render {
        let tile = 128;
        let seen = input_preview(&photo.network_input(tile, &what)?, tile);
        let scene = SceneConfig::default().build()?;
        let settings =
            RenderSettings { size: tile, spp: 32, seed: 0, jitter: true, sampler: Sampler::Sobol };
        let image = render(&scene, &MerlBrdf::new(&table), &settings, progress)?;
        let mut sheet = Srgb8Image::filled(2 * tile, tile, [0, 0, 0]);
        sheet.blit(&seen, 0, 0);
        sheet.blit(&image.to_srgb8(&Tonemap::default(), [0, 0, 0]), tile, 0);
        sheet.write_png(path)?;
        eprintln!(
            "wrote {} (input as the network sees it | recovered, on a sphere)",
            path.display()
        );
    }
    Ok(())
}
