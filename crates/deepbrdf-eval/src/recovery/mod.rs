//! Single-image recovery (§5.2) on the library side: what the recovery networks learn (the
//! targets: DeepBRDF's latent or the 7 Lambertian + GGX attributes of §5.1), the baselines
//! DeepBRDF's recovery is measured against (the training mean, the nearest neighbour) and the
//! novel scenes the recovered tables are compared in.
mod baselines;
mod novel;
mod targets;

pub use baselines::{mean_table, nearest_materials, render_input};
pub use novel::{novel_scene, NOVEL_SEED};
pub use targets::{
    attribute_fits, attribute_targets, attributes_from_targets, latents, ATTRIBUTE_TARGETS,
};
