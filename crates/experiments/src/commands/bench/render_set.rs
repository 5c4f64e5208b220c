//! `experiments bench render-set`: images per second of the recovery render set (§5.2) at its
//! CPU default (64x64 px, 16 spp): `--images` images of the first `--materials` `merl`
//! materials rendered into a temporary folder, the per-material sampler builds included, as
//! `render-set` spends them.
use crate::args::data::CacheArg;
use deepbrdf_data::bundled::Collection;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::Progress;
use deepbrdf_render::{RenderSet, Sampler, SceneSampler, SetHeader};
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Images to render.
    #[arg(long, default_value_t = 60)]
    pub images: usize,
    /// Materials they cycle through (the first of `merl`).
    #[arg(long, default_value_t = 6)]
    pub materials: usize,
    #[arg(long, default_value_t = 64)]
    pub size: u32,
    #[arg(long, default_value_t = 16)]
    pub spp: u32,
    #[command(flatten)]
    pub cache: CacheArg,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let names = Collection::Merl.names()?;
    let materials: Vec<String> =
        names.iter().take(args.materials.max(1)).map(|n| format!("merl/{n}")).collect();
    let header = SetHeader {
        data: "merl".into(),
        materials,
        excluded: Vec::new(),
        seed: 0,
        size: args.size,
        spp: args.spp,
        exr: false,
        sampler: SceneSampler::default(),
        pixel_sampler: Sampler::Sobol,
    };
    let set = RenderSet::plan(header, args.images)?;
    let cache = args.cache.cache();
    // Tables loaded (tabulated into the cache) before the clock starts.
    for m in &set.header.materials {
        load_material(m, &cache)?;
    }
    let dir = tempfile::tempdir()?;
    let load = |spec: &str| load_material(spec, &cache).map(|(_, t)| t).map_err(|e| e.to_string());
    let start = Instant::now();
    let cpu0 = super::cpu_time::cpu_seconds().unwrap_or(0.0);
    let n = set.render_missing(dir.path(), &load, progress)?;
    let (wall, cpu) =
        (start.elapsed().as_secs_f64(), super::cpu_time::cpu_seconds().unwrap_or(0.0) - cpu0);
    println!(
        "render set: {n} images of {} materials, {}x{} px, {} spp: {wall:.2} s wall, {cpu:.2} s \
         CPU -> {:.2} images/s ({:.3} s of CPU per image); 2000 images would take ~{:.0} s",
        set.header.materials.len(),
        args.size,
        args.size,
        args.spp,
        n as f64 / wall,
        cpu / n.max(1) as f64,
        2000.0 * wall / n.max(1) as f64
    );
    Ok(())
}
