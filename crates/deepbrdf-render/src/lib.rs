//! `deepbrdf-render`: a physically based renderer of measured BRDFs, for the paper's image-space evaluation
//! (RelAE, Figs. 4, 6-9) and its synthetic recovery training set (§5.2: objects under sun-and-sky
//! lighting). Direct illumination of one analytic shape at the origin; see [`integrator`] for the
//! estimator.
//!
//! ```text
//! SceneConfig --build--> Scene { shape, camera, lighting }
//! render(&scene, &brdf, &RenderSettings, progress) -> Image  --> EXR / PNG / contact sheet
//! ```

pub mod brdf;
pub mod camera;
pub mod distribution;
pub mod error;
pub mod geometry;
pub mod image;
pub mod integrator;
pub mod light;
pub mod photo;
pub mod render_set;
pub mod sampler;
pub mod scene;
pub mod scene_sampler;
pub mod shape;
pub mod sheet;
pub mod sky;

pub use brdf::{
    Brdf, Ggx, Lambertian, MerlBrdf, MerlLookup, MerlSampling, SamplingLobe, Sum, TableSampler,
};
pub use camera::{Camera, Projection};
pub use error::{RenderError, Result};
pub use image::{Image, Srgb8Image, Tonemap};
pub use integrator::{render, RenderSettings};
pub use light::{DirectionalLight, Environment, LightSpec, Lighting};
pub use photo::Photo;
pub use render_set::{RenderSet, SetHeader, SetImage};
pub use sampler::Sampler;
pub use scene::{Scene, SceneConfig};
pub use scene_sampler::{camera_png, SampledScene, SceneSampler};
pub use shape::Shape;
pub use sheet::{contact_sheet, SheetConfig, Tile};
pub use sky::{SunSky, SunSkyConfig};
