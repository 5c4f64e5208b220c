//! What single-image recovery (§5.2) reads from a render set, in one place for `train-recovery`,
//! `recover` and `figures-recovery`: the images prepared for the network
//! (`deepbrdf_render::Photo`) and the materials' tables. The targets the networks learn are the
//! library's ([`deepbrdf_eval::recovery`]).
use anyhow::Context;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_render::{Photo, RenderSet};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;

/// The images of a render set prepared for a network: those the network can use, and why the
/// others cannot (the checks of [`Photo::network_input`]: no object, no dark background,
/// saturated). A render set is drawn at random, so a dark material under a low sun can give an
/// image a camera would also get; `recover` refuses such a photo, so training and measuring
/// skip it rather than learn from or score a guess.
#[derive(Debug)]
pub struct SetImages {
    /// Indices (into the set's images) of the usable images, in the order given.
    pub indices: Vec<usize>,
    /// Their network inputs, `[3, side, side]` each, concatenated in `indices`' order.
    pub pixels: Vec<f32>,
    /// The unusable images: index and the reason.
    pub unusable: Vec<(usize, String)>,
}

impl SetImages {
    /// One line for the user: how many images were skipped, and the first reason.
    pub fn note(&self, dir: &Path) -> Option<String> {
        let (_, why) = self.unusable.first()?;
        Some(format!(
            "note: {}: {} of {} images skipped as unusable ({why})",
            dir.display(),
            self.unusable.len(),
            self.unusable.len() + self.indices.len()
        ))
    }
}

/// The images of `set` (in `dir`) with these indices, prepared for a network of input side
/// `side`. Errors name the first missing or unreadable image, or say that none is usable.
pub fn set_images(
    set: &RenderSet,
    dir: &Path,
    indices: &[usize],
    side: usize,
    progress: &dyn Progress,
) -> anyhow::Result<SetImages> {
    let missing = indices.iter().filter(|&&i| !set.is_complete(dir, i)).count();
    if missing > 0 {
        anyhow::bail!(
            "{}: {missing} of the set's images are missing; rerun `experiments render-set` with \
             the same arguments to finish it",
            dir.display()
        );
    }
    progress.start(indices.len() as u64, "reading images");
    let read = indices
        .par_iter()
        .map(|&i| {
            let path = set.paths(dir, i).0;
            let photo = Photo::read(&path)?;
            let input = photo.network_input(side as u32, &format!("image {i}"));
            progress.advance(1);
            Ok((i, input))
        })
        .collect::<anyhow::Result<Vec<_>>>();
    progress.finish();
    let mut out = SetImages { indices: Vec::new(), pixels: Vec::new(), unusable: Vec::new() };
    for (i, input) in read? {
        match input {
            Ok(pixels) => {
                out.indices.push(i);
                out.pixels.extend_from_slice(&pixels);
            }
            Err(e) => out.unusable.push((i, e.to_string())),
        }
    }
    if out.indices.is_empty() && !indices.is_empty() {
        anyhow::bail!(
            "{}: none of the {} images is usable ({})",
            dir.display(),
            indices.len(),
            out.unusable[0].1
        );
    }
    Ok(out)
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
