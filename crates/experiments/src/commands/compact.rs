//! `experiments compact PATH...`: rewrites committed outputs in their compact, lossless forms,
//! in place (maintainers: the repository's tracked size). A model directory (or a training
//! directory holding `model/`) is loaded and saved again, its weights and median reference
//! packed (`deepbrdf_data::packed`), with its id checked unchanged; a recovery network
//! directory the same; an `.svg` chart is rewritten in the compact form the chart writer now
//! writes (`deepbrdf_eval::figures::compact`); an RGB `.png` is re-encoded at the PNG writer's
//! best compression (the same pixels); a folder holding a harness run has its charts redrawn
//! from its `results.csv` by the chart writer; a folder is searched for all of these. What is
//! already compact is left as it is.
use anyhow::{bail, Context};
use deepbrdf_data::Progress;
use deepbrdf_eval::figures::compact_svg;
use deepbrdf_eval::harness::Results;
use deepbrdf_model::recovery::artifact::{RecoveryArtifact, RECOVERY_MANIFEST};
use deepbrdf_model::ModelArtifact;
use deepbrdf_render::Srgb8Image;
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Model or recovery network directories, `.svg` files, or folders holding them.
    #[arg(required = true)]
    pub paths: Vec<PathBuf>,
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let (mut before, mut after) = (0u64, 0u64);
    for path in &args.paths {
        let (b, a) = compact_path(path)?;
        before += b;
        after += a;
    }
    println!("{} -> {} bytes", before, after);
    Ok(())
}

/// Compacts `path`; returns its bytes before and after.
fn compact_path(path: &Path) -> anyhow::Result<(u64, u64)> {
    if path.is_dir() {
        if path.join(deepbrdf_model::autoencoder::artifact::MANIFEST_FILE).is_file() {
            return resave(
                path,
                |dir| {
                    let model = ModelArtifact::load(dir)?;
                    model.save(dir)?;
                    Ok(model.id().to_string())
                },
                |dir| Ok(ModelArtifact::load(dir)?.id().to_string()),
            );
        }
        if path.join(RECOVERY_MANIFEST).is_file() {
            return resave(
                path,
                |dir| {
                    let network = RecoveryArtifact::load(dir)?;
                    network.save(dir)?;
                    Ok(network.id().to_string())
                },
                |dir| Ok(RecoveryArtifact::load(dir)?.id().to_string()),
            );
        }
        if is_harness_run(path) {
            Results::read(path)?.write_charts(path)?;
            println!("{}: charts redrawn from results.csv", path.display());
        }
        let mut entries: Vec<PathBuf> = std::fs::read_dir(path)
            .with_context(|| format!("{}", path.display()))?
            .map(|e| e.map(|e| e.path()))
            .collect::<std::io::Result<_>>()
            .with_context(|| format!("{}", path.display()))?;
        entries.sort();
        let mut total = (0, 0);
        for entry in entries.iter().filter(|e| e.is_dir() || is_svg(e) || is_png(e)) {
            let (b, a) = compact_path(entry)?;
            total = (total.0 + b, total.1 + a);
        }
        return Ok(total);
    }
    if is_png(path) {
        return compact_png(path);
    }
    if !is_svg(path) {
        bail!(
            "{}: not a model or recovery network directory, an .svg or .png file or a folder",
            path.display()
        );
    }
    let svg = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let compact = compact_svg(&svg);
    if compact != svg {
        deepbrdf_data::files::write_atomic(path, compact.as_bytes())?;
        println!("{}: {} -> {} bytes", path.display(), svg.len(), compact.len());
    }
    Ok((svg.len() as u64, compact.len() as u64))
}

fn is_svg(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "svg")
}

fn is_png(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "png")
}

/// Whether `dir` holds a harness run (`Results::write`'s files), whose charts can be redrawn.
fn is_harness_run(dir: &Path) -> bool {
    let header = std::fs::read_to_string(dir.join("results.csv"))
        .is_ok_and(|t| t.starts_with("method,k,fold,material,measure,value\n"));
    header && dir.join("summary.md").is_file() && dir.join("fits.csv").is_file()
}

/// An RGB PNG re-encoded as the project's writer now encodes it (the same pixels, best
/// compression), kept only where smaller; other PNGs are left as they are.
fn compact_png(path: &Path) -> anyhow::Result<(u64, u64)> {
    let png = std::fs::read(path).with_context(|| format!("{}", path.display()))?;
    let Some(image) = Srgb8Image::from_png(path, &png)? else {
        return Ok((png.len() as u64, png.len() as u64));
    };
    let compact = image.png_bytes()?;
    if compact.len() >= png.len() {
        return Ok((png.len() as u64, png.len() as u64));
    }
    deepbrdf_data::files::write_atomic(path, &compact)?;
    println!("{}: {} -> {} bytes", path.display(), png.len(), compact.len());
    Ok((png.len() as u64, compact.len() as u64))
}

/// Saves the artifact in `dir` again with `save` (which returns its id), then loads it with
/// `load` and checks the id is unchanged; returns the directory's bytes before and after.
fn resave(
    dir: &Path,
    save: impl Fn(&Path) -> deepbrdf_model::Result<String>,
    load: impl Fn(&Path) -> deepbrdf_model::Result<String>,
) -> anyhow::Result<(u64, u64)> {
    let before = dir_bytes(dir)?;
    let id = save(dir)?;
    let reloaded = load(dir)?;
    if reloaded != id {
        bail!("{}: id {reloaded} after rewriting, {id} before", dir.display());
    }
    let after = dir_bytes(dir)?;
    println!("{}: id {id} unchanged, {before} -> {after} bytes", dir.display());
    Ok((before, after))
}

/// The bytes of the files directly in `dir`.
fn dir_bytes(dir: &Path) -> anyhow::Result<u64> {
    let mut total = 0;
    for entry in std::fs::read_dir(dir).with_context(|| format!("{}", dir.display()))? {
        let meta = entry.with_context(|| format!("{}", dir.display()))?.metadata()?;
        if meta.is_file() {
            total += meta.len();
        }
    }
    Ok(total)
}
