//! `experiments render-set --out DIR`: the synthetic training set of single-image recovery
//! (§5.2): `--images N` renders of one material each, on a random shape from a random viewpoint
//! under a random sun and sky (`deepbrdf_render::scene_sampler`), as camera-like PNGs (exposure,
//! noise) and optionally linear EXRs, with `manifest.json`. Deterministic with `--seed`,
//! parallel, resumable (rerun the same command: only missing images are rendered).
//! `--exclude-fold I/N` leaves out the materials of fold I of the harness's N-fold split
//! (`deepbrdf_eval::harness::Mode::KFold`, seed `--fold-seed`), `--only-fold I/N` keeps only
//! them (the held-out test images).
use crate::args::data::{cache_at, DataArgs};
use anyhow::{bail, Context};
use deepbrdf_data::dataset::{binary_files, load_material, DataSource};
use deepbrdf_data::lock::FolderLock;
use deepbrdf_data::Progress;
use deepbrdf_eval::harness::Mode;
use deepbrdf_render::{RenderSet, Sampler, SceneSampler, SetHeader, Shape};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output folder (created; an existing set there is resumed or extended).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Number of images (material i mod n for image i).
    #[arg(long, default_value_t = 2000)]
    pub images: usize,
    /// Image side in pixels (the paper: 256).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(8..=4096))]
    pub size: u32,
    /// Samples per pixel.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub spp: u32,
    /// Seed of the scenes, renders and noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Shapes to draw from (comma-separated; default: sphere, plane, torus, ellipsoid,
    /// cylinder).
    #[arg(long, value_delimiter = ',')]
    pub shapes: Vec<String>,
    /// Leave out the materials of fold I of the N-fold split of the data (I from 0).
    #[arg(long, value_name = "I/N", conflicts_with = "only_fold")]
    pub exclude_fold: Option<String>,
    /// Render only the materials of fold I of the N-fold split.
    #[arg(long, value_name = "I/N")]
    pub only_fold: Option<String>,
    /// Seed of the k-fold split (the harness's `--seed`, default as in `baselines`).
    #[arg(long, default_value_t = 0)]
    pub fold_seed: u64,
    /// Also write each image's linear radiance (coverage as alpha) as EXR.
    #[arg(long)]
    pub exr: bool,
    /// The renderer's random numbers: sobol or independent (a set made before this choice
    /// existed was rendered with independent: extend it with `--sampler independent`).
    #[arg(long = "sampler", default_value = "sobol")]
    pub pixel_sampler: Sampler,
    #[command(flatten)]
    pub data: DataArgs,
}

/// `I/N` parsed and checked.
pub fn parse_fold(s: &str) -> anyhow::Result<(usize, usize)> {
    let parsed = s.split_once('/').and_then(|(i, n)| {
        Some((i.trim().parse::<usize>().ok()?, n.trim().parse::<usize>().ok()?))
    });
    match parsed {
        Some((i, n)) if n >= 2 && i < n => Ok((i, n)),
        _ => bail!("fold '{s}': expected I/N with N >= 2 and 0 <= I < N (e.g. 0/5)"),
    }
}

/// The data's materials as `load_material` names them, in dataset order.
pub fn material_specs(data: &DataArgs) -> anyhow::Result<Vec<String>> {
    Ok(match data.source() {
        DataSource::Bundled(c) => c.names()?.iter().map(|n| format!("{c}/{n}")).collect(),
        DataSource::Folder(dir) => {
            binary_files(&dir)?.iter().map(|p| p.display().to_string()).collect()
        }
    })
}

/// The materials of fold `i` of the `n`-fold split of `count` materials (the harness's split).
pub fn fold_members(i: usize, n: usize, count: usize, seed: u64) -> anyhow::Result<Vec<usize>> {
    let folds = Mode::KFold { folds: n }.folds(count, 0, seed)?;
    Ok(folds[i].test.clone())
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let all = material_specs(&args.data)?;
    let (materials, excluded) = match (&args.exclude_fold, &args.only_fold) {
        (Some(f), None) | (None, Some(f)) => {
            let (i, n) = parse_fold(f)?;
            let test = fold_members(i, n, all.len(), args.fold_seed)?;
            let (mut kept, mut left) = (Vec::new(), Vec::new());
            for (j, m) in all.iter().enumerate() {
                let in_fold = test.contains(&j);
                if in_fold == args.only_fold.is_some() {
                    kept.push(m.clone());
                } else {
                    left.push(m.clone());
                }
            }
            (kept, left)
        }
        _ => (all, Vec::new()),
    };
    let mut sampler = SceneSampler::default();
    if !args.shapes.is_empty() {
        sampler.shapes =
            args.shapes.iter().map(|s| s.parse::<Shape>()).collect::<Result<_, _>>()?;
    }
    let header = SetHeader {
        data: args.data.source().label(),
        materials,
        excluded,
        seed: args.seed,
        size: args.size,
        spp: args.spp,
        exr: args.exr,
        sampler,
        pixel_sampler: args.pixel_sampler,
    };
    let set = RenderSet::plan(header, args.images)?;
    let _lock = FolderLock::acquire(&args.out)?;
    check_existing(&args.out, &set)?;
    set.save(&args.out)?;
    let cache = cache_at(args.data.cache.dir.as_deref());
    let load = |spec: &str| load_material(spec, &cache).map(|(_, t)| t).map_err(|e| e.to_string());
    let start = Instant::now();
    let rendered = set.render_missing(&args.out, &load, progress)?;
    let seconds = start.elapsed().as_secs_f64();
    println!(
        "{}: {} images of {} materials ({}x{} px, {} spp), {rendered} rendered in {seconds:.1} s \
         ({:.1} images/s), {} already there",
        args.out.display(),
        set.images.len(),
        set.header.materials.len(),
        args.size,
        args.size,
        args.spp,
        rendered as f64 / seconds.max(1e-9),
        set.images.len() - rendered
    );
    Ok(())
}

/// An existing set in `dir` must have the same header (it is resumed or extended); a folder
/// with other files but no manifest is not written into.
fn check_existing(dir: &Path, set: &RenderSet) -> anyhow::Result<()> {
    if dir.join(deepbrdf_render::render_set::SET_MANIFEST).is_file() {
        let old = RenderSet::load(dir)?;
        if old.header != set.header {
            bail!(
                "{} holds a render set with other settings (data, materials, seed, size, spp, \
                 shapes or --exr); choose another --out",
                dir.display()
            );
        }
        return Ok(());
    }
    let foreign = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok())
        .any(|e| !e.file_name().to_string_lossy().starts_with('.'));
    if foreign {
        bail!("{} is not empty and holds no render set; choose another --out", dir.display());
    }
    Ok(())
}
