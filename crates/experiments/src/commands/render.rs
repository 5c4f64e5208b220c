//! `experiments render`: renders one material (a MERL .binary file or a bundled material) to a
//! tonemapped PNG and, optionally, a linear OpenEXR.
use crate::args::data::CacheArg;
use crate::args::scene::SceneArgs;
use anyhow::Context;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::Progress;
use deepbrdf_render::{render, MerlBrdf};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// A MERL .binary file or a bundled material (chrome, merl/chrome, rgl/...).
    pub material: String,
    /// Output PNG (tonemapped sRGB).
    #[arg(short, long, value_name = "PNG")]
    pub output: PathBuf,
    /// Also write the linear radiance (and coverage as alpha) as OpenEXR.
    #[arg(long, value_name = "EXR")]
    pub exr: Option<PathBuf>,
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub cache: CacheArg,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let setup = args.scene.setup(256)?;
    let (name, table) = load_material(&args.material, &args.cache.cache())
        .with_context(|| format!("loading material '{}'", args.material))?;
    let start = Instant::now();
    let image = render(&setup.scene, &MerlBrdf::new(&table), &setup.settings, progress)?;
    let seconds = start.elapsed().as_secs_f64();
    image.write_png(&args.output, &setup.tonemap)?;
    if let Some(exr) = &args.exr {
        image.write_exr(exr)?;
    }
    println!(
        "{name}: {}, seed {}, rendered in {seconds:.2} s -> {}{}",
        setup.description(),
        setup.settings.seed,
        args.output.display(),
        args.exr.as_ref().map(|p| format!(", {}", p.display())).unwrap_or_default()
    );
    Ok(())
}
