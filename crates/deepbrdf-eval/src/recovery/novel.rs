//! The novel scene a recovered table is judged in: another shape, view and sky than the input
//! image's, since the input view alone rewards copying its highlights.
use deepbrdf_render::{RenderSet, SceneConfig, SceneSampler, Shape};

/// Seed offset of the novel scenes (another stream than the inputs').
pub const NOVEL_SEED: u64 = 0x6e6f_7665_6c;

/// The novel scene of image `i` of `set`: drawn from another stream than the inputs', with
/// another shape than the input's (the sampler's next shape when the draw repeats it; a plane
/// is then seen at most as steeply as the sampler views planes).
pub fn novel_scene(set: &RenderSet, i: usize) -> SceneConfig {
    let sampler = SceneSampler::default();
    let mut scene = sampler.sample(set.header.seed ^ NOVEL_SEED, i as u64).scene;
    let input = set.images[i].scene.scene.shape;
    if scene.shape.name() == input.name() {
        let k = sampler.shapes.iter().position(|s| s.name() == input.name()).unwrap_or(0);
        scene.shape = sampler.shapes[(k + 1) % sampler.shapes.len()];
        if matches!(scene.shape, Shape::Plane { .. }) {
            scene.view_theta_deg = scene.view_theta_deg.min(sampler.plane_view_theta_deg[1]);
        }
    }
    scene
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recovery::baselines::tests::tiny_set;

    #[test]
    fn the_novel_scene_never_shows_the_inputs_shape_and_is_deterministic() {
        let set = tiny_set(12);
        for i in 0..set.images.len() {
            let novel = novel_scene(&set, i);
            assert_ne!(novel.shape.name(), set.images[i].scene.scene.shape.name(), "image {i}");
            assert_eq!(novel, novel_scene(&set, i));
        }
    }
}
