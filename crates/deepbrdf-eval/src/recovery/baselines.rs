//! The baselines single-image recovery (§5.2) is measured against: the training mean (the
//! per-value mean of the training materials, what a method that ignores the image gets) and the
//! nearest neighbour (the training material whose render in the input's own scene is closest to
//! the input: retrieval instead of a network).
use crate::error::{EvalError, Result};
use deepbrdf_data::merl::{CELLS, INVALID_VALUE, VALUES};
use deepbrdf_data::{MerlTable, Progress, Silent};
use deepbrdf_render::{
    camera_png, render, Brdf, MerlBrdf, Photo, RenderSet, RenderSettings, Sampler, Scene,
};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// The per-value mean of `tables` over the cells valid in all of them (others invalid).
pub fn mean_table(tables: &[&MerlTable]) -> Result<MerlTable> {
    if tables.is_empty() {
        return Err(EvalError::Invalid("no training material for the mean".into()));
    }
    let mut values = vec![0f32; VALUES];
    values.par_chunks_mut(CELLS).enumerate().for_each(|(c, out)| {
        for (cell, v) in out.iter_mut().enumerate() {
            let i = c * CELLS + cell;
            if tables.iter().all(|t| t.is_valid(cell)) {
                *v = (tables.iter().map(|t| f64::from(t.values()[i])).sum::<f64>()
                    / tables.len() as f64) as f32;
            } else {
                *v = INVALID_VALUE;
            }
        }
    });
    Ok(MerlTable::from_values(values)?)
}

/// Image `i` of `set` rendered with `brdf` in its own scene (`scene`, built from the image's;
/// its seed and exposure, `spp` Sobol samples, no noise), prepared for a network of input side
/// `side` as the input is; `None` when the render fails or is unusable as an input.
pub fn render_input(
    set: &RenderSet,
    i: usize,
    scene: &Scene,
    brdf: &dyn Brdf,
    spp: u32,
    side: usize,
) -> Option<Vec<f32>> {
    let image = &set.images[i];
    let settings = RenderSettings {
        size: set.header.size,
        spp,
        seed: image.scene.render_seed,
        jitter: true,
        sampler: Sampler::Sobol,
    };
    let linear = render(scene, brdf, &settings, &Silent).ok()?;
    let png = camera_png(&linear, image.scene.exposure, 0.0, 0);
    Photo::from_srgb8(&png).network_input(side as u32, &image.material).ok()
}

/// For each image of `set` with these indices (`inputs`, `[3, side, side]` each, in their
/// order), the name of the training material whose [`render_input`] is closest to the input
/// (squared distance; the first in name order on a tie). Errors when no training material
/// renders to a usable image in some image's scene.
pub fn nearest_materials(
    set: &RenderSet,
    indices: &[usize],
    inputs: &[f32],
    side: usize,
    train: &BTreeMap<String, MerlTable>,
    spp: u32,
    progress: &dyn Progress,
) -> Result<Vec<String>> {
    let per = 3 * side * side;
    let n = indices.len();
    if inputs.len() != n * per {
        return Err(EvalError::Invalid(format!(
            "{} input values for {n} images of side {side}, expected {}",
            inputs.len(),
            n * per
        )));
    }
    let mut best = vec![(f64::INFINITY, String::new()); n];
    let scenes: Vec<Scene> = indices
        .iter()
        .map(|&i| set.images[i].scene.scene.build())
        .collect::<std::result::Result<Vec<_>, _>>()?;
    progress.start(train.len() as u64, "nearest neighbours");
    for (name, table) in train {
        let brdf = MerlBrdf::new(table);
        let distances: Vec<f64> = (0..n)
            .into_par_iter()
            .map(|j| match render_input(set, indices[j], &scenes[j], &brdf, spp, side) {
                Some(x) => x
                    .iter()
                    .zip(&inputs[j * per..(j + 1) * per])
                    .map(|(a, b)| f64::from(a - b).powi(2))
                    .sum(),
                None => f64::INFINITY,
            })
            .collect();
        for (b, d) in best.iter_mut().zip(distances) {
            if d < b.0 {
                *b = (d, name.clone());
            }
        }
        progress.advance(1);
    }
    progress.finish();
    if let Some(j) = best.iter().position(|b| b.1.is_empty()) {
        return Err(EvalError::Invalid(format!(
            "image {}: no training material renders to a usable image in its scene",
            indices[j]
        )));
    }
    Ok(best.into_iter().map(|b| b.1).collect())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use deepbrdf_data::testing::{sparse_table, synthetic_table};
    use deepbrdf_render::{SceneSampler, SetHeader};

    /// A render set of `count` images (manifest only) cycling through materials `a` and `b`.
    pub(crate) fn tiny_set(count: usize) -> RenderSet {
        let header = SetHeader {
            data: "synthetic".into(),
            materials: vec!["a".into(), "b".into()],
            excluded: vec![],
            seed: 5,
            size: 24,
            spp: 4,
            exr: false,
            sampler: SceneSampler::default(),
            pixel_sampler: Sampler::Sobol,
        };
        RenderSet::plan(header, count).unwrap()
    }

    #[test]
    fn the_mean_table_averages_cells_valid_in_every_table_and_drops_the_others() {
        let (a, b, sparse) = (synthetic_table(1), synthetic_table(6), sparse_table(2));
        let mean = mean_table(&[&a, &b]).unwrap();
        for i in (0..VALUES).step_by(7919) {
            let expected = ((f64::from(a.values()[i]) + f64::from(b.values()[i])) / 2.0) as f32;
            if a.is_valid(i % CELLS) && b.is_valid(i % CELLS) {
                assert_eq!(mean.values()[i], expected, "value {i}");
            }
        }
        let with_sparse = mean_table(&[&a, &sparse]).unwrap();
        let dropped = (0..CELLS).find(|&c| a.is_valid(c) && !sparse.is_valid(c)).unwrap();
        assert!(!with_sparse.is_valid(dropped));
        let e = mean_table(&[]).unwrap_err().to_string();
        assert!(e.contains("no training material"), "{e}");
    }

    #[test]
    fn an_input_rendered_from_a_training_material_finds_that_material() {
        let set = tiny_set(4);
        let side = 16;
        let train: BTreeMap<String, MerlTable> =
            [("a".to_string(), synthetic_table(0)), ("b".to_string(), synthetic_table(5))].into();
        let mut indices = Vec::new();
        let mut inputs = Vec::new();
        for (i, image) in set.images.iter().enumerate() {
            let scene = image.scene.scene.build().unwrap();
            let brdf = MerlBrdf::new(&train[&image.material]);
            if let Some(x) = render_input(&set, i, &scene, &brdf, 2, side) {
                indices.push(i);
                inputs.extend(x);
            }
        }
        assert!(!indices.is_empty(), "no usable input in the tiny set");
        let nearest = nearest_materials(&set, &indices, &inputs, side, &train, 2, &Silent).unwrap();
        for (&i, name) in indices.iter().zip(&nearest) {
            assert_eq!(name, &set.images[i].material, "image {i}");
        }
        let e = nearest_materials(&set, &indices, &inputs[1..], side, &train, 2, &Silent);
        assert!(e.unwrap_err().to_string().contains("input values"));
    }
}
