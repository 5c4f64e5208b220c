//! What single-image recovery (§5.2) reads from a render set, in one place for `train-recovery`,
//! `recover` and `figures-recovery`: the images prepared for the network
//! (`deepbrdf_render::Photo`), and the targets of a material: DeepBRDF's latent (eq. 2) or the
//! 7 Lambertian + GGX attributes of §5.1 (roughness as its logarithm, the scale it varies on).
use anyhow::Context;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::attributes::{fit, Attributes, FitConfig, MAX_ROUGHNESS, MIN_ROUGHNESS};
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::{Photo, RenderSet};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;

/// The images of `set` (in `dir`) with these indices, prepared for a network of input side
/// `side`, concatenated `[3, side, side]` each. Errors name the first missing or unusable image.
pub fn set_images(
    set: &RenderSet,
    dir: &Path,
    indices: &[usize],
    side: usize,
    progress: &dyn Progress,
) -> anyhow::Result<Vec<f32>> {
    let missing = indices.iter().filter(|&&i| !set.is_complete(dir, i)).count();
    if missing > 0 {
        anyhow::bail!(
            "{}: {missing} of the set's images are missing; rerun `experiments render-set` with \
             the same arguments to finish it",
            dir.display()
        );
    }
    progress.start(indices.len() as u64, "reading images");
    let images = indices
        .par_iter()
        .map(|&i| {
            let path = set.paths(dir, i).0;
            let photo = Photo::read(&path)?;
            let input = photo.network_input(side as u32, &path.display().to_string())?;
            progress.advance(1);
            Ok(input)
        })
        .collect::<anyhow::Result<Vec<Vec<f32>>>>();
    progress.finish();
    Ok(images?.concat())
}

/// Loads each distinct material of `names` once.
pub fn load_tables(
    names: &[String],
    cache: &deepbrdf_data::cache::Cache,
    progress: &dyn Progress,
) -> anyhow::Result<BTreeMap<String, MerlTable>> {
    let mut distinct: Vec<&String> = names.iter().collect();
    distinct.sort();
    distinct.dedup();
    progress.start(distinct.len() as u64, "loading materials");
    let tables = distinct
        .par_iter()
        .map(|&name| {
            let table = load_material(name, cache).with_context(|| format!("loading {name}"))?.1;
            progress.advance(1);
            Ok((name.clone(), table))
        })
        .collect::<anyhow::Result<BTreeMap<_, _>>>();
    progress.finish();
    tables
}

/// DeepBRDF's latent of each table.
pub fn latents(
    model: &DeepBrdf,
    tables: &BTreeMap<String, MerlTable>,
) -> anyhow::Result<BTreeMap<String, Vec<f32>>> {
    tables.iter().map(|(n, t)| Ok((n.clone(), model.encode(t)?))).collect()
}

/// The 7 targets of attributes: diffuse RGB, specular RGB, ln(roughness).
pub fn attribute_targets(a: &Attributes) -> Vec<f32> {
    let v = a.to_array();
    vec![
        v[0] as f32,
        v[1] as f32,
        v[2] as f32,
        v[3] as f32,
        v[4] as f32,
        v[5] as f32,
        v[6].ln() as f32,
    ]
}

/// Attributes from 7 predicted targets, clamped into their ranges.
pub fn attributes_of(targets: &[f32]) -> anyhow::Result<Attributes> {
    anyhow::ensure!(targets.len() == 7, "7 attribute outputs expected, got {}", targets.len());
    let t: Vec<f64> = targets.iter().map(|&v| f64::from(v)).collect();
    let albedo = |v: f64| v.clamp(0.0, 1.0);
    let values = [
        albedo(t[0]),
        albedo(t[1]),
        albedo(t[2]),
        albedo(t[3]),
        albedo(t[4]),
        albedo(t[5]),
        t[6].exp().clamp(MIN_ROUGHNESS, MAX_ROUGHNESS),
    ];
    Ok(Attributes::from_slice(&values)?)
}

/// The Lambertian + GGX fit of each table, as targets.
pub fn attribute_fits(
    tables: &BTreeMap<String, MerlTable>,
    progress: &dyn Progress,
) -> anyhow::Result<BTreeMap<String, Vec<f32>>> {
    progress.start(tables.len() as u64, "fitting attributes");
    let mut out = BTreeMap::new();
    for (name, table) in tables {
        let f = fit(table, &FitConfig::default()).with_context(|| format!("fitting {name}"))?;
        out.insert(name.clone(), attribute_targets(&f.attributes));
        progress.advance(1);
    }
    progress.finish();
    Ok(out)
}
