//! `experiments compare`: renders two materials under the same settings, prints RelAE (the
//! paper's image-space error), RMSE and PSNR of the tonemapped images, and writes a false-colour
//! difference image.
use crate::args::data::CacheArg;
use crate::args::scene::SceneArgs;
use anyhow::Context;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::Progress;
use deepbrdf_eval::metrics::{compare_images, difference_image};
use deepbrdf_render::brdf::MeasuredBrdf;
use deepbrdf_render::{render, MerlBrdf};
use std::path::PathBuf;

use crate::args::measurement::load_evaluator;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The reference: a MERL .binary file or a bundled material.
    pub a: String,
    /// The material compared with it (e.g. a reconstruction's .binary file).
    pub b: String,
    /// Output PNG of |B - A| per pixel in false colour (inferno map).
    #[arg(short, long, value_name = "PNG")]
    pub output: PathBuf,
    /// Error at which the colour map saturates, relative to A's mean pixel value on the object.
    #[arg(long, default_value_t = 0.5)]
    pub scale: f64,
    /// Render B straight from the RGL evaluator instead of its MERL table (B must be a `.bsdf`
    /// file or an `rgl-measured/NAME`): `compare rgl-measured/X rgl-measured/X --evaluator`
    /// measures what converting X to the MERL grid changes in the image.
    #[arg(long)]
    pub evaluator: bool,
    /// Render A straight from the RGL evaluator instead of its MERL table (A must be a `.bsdf` file or an
    /// `rgl-measured/NAME`), still sampled by A's MERL table: `compare rgl-measured/X OUT.bsdf
    /// --evaluator-a --evaluator` measures an exported file against the original measurement.
    #[arg(long)]
    pub evaluator_a: bool,
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub cache: CacheArg,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let setup = args.scene.setup(256)?;
    let cache = args.cache.cache();
    let (name_a, a) =
        load_material(&args.a, &cache).with_context(|| format!("loading material '{}'", args.a))?;
    let (name_b, b) =
        load_material(&args.b, &cache).with_context(|| format!("loading material '{}'", args.b))?;
    // Both rendered with A's sampling and the same seed: the same directions are drawn, so the
    // difference is the materials', not Monte Carlo noise.
    let brdf_a = MerlBrdf::new(&a);
    let image_a = if args.evaluator_a {
        let measured = load_evaluator(&args.a, "A", "--evaluator-a")?;
        let brdf = MeasuredBrdf { brdf: &measured, sampling: &brdf_a };
        render(&setup.scene, &brdf, &setup.settings, progress)?
    } else {
        render(&setup.scene, &brdf_a, &setup.settings, progress)?
    };
    let image_b = if args.evaluator {
        let measured = load_evaluator(&args.b, "B", "--evaluator")?;
        let brdf = MeasuredBrdf { brdf: &measured, sampling: &brdf_a };
        render(&setup.scene, &brdf, &setup.settings, progress)?
    } else {
        let brdf_b = MerlBrdf::new_sampled(&b, brdf_a.sampling().clone());
        render(&setup.scene, &brdf_b, &setup.settings, progress)?
    };
    let name_b = if args.evaluator { format!("{name_b} (evaluator)") } else { name_b };
    let name_a = if args.evaluator_a { format!("{name_a} (evaluator)") } else { name_a };
    let c = compare_images(&image_b, &image_a, &setup.tonemap)?;
    difference_image(&image_b, &image_a, args.scale)?.write_png(&args.output)?;
    println!(
        "{name_b} vs {name_a} ({}): RelAE {:.4}  RMSE {:.4}  PSNR {:.2} dB -> {}",
        setup.description(),
        c.relae,
        c.rmse,
        c.psnr,
        args.output.display()
    );
    Ok(())
}
