//! A scene: one shape at the origin, a camera and the lighting; [`SceneConfig`] owns its
//! construction (the lighting's tables are built once per scene).

use super::camera::{Camera, Projection};
use super::light::{LightSpec, Lighting};
use super::shape::Shape;
use crate::error::Result;
use serde::{Deserialize, Serialize};

/// Everything that defines a scene, serialisable next to the images rendered from it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneConfig {
    pub shape: Shape,
    pub light: LightSpec,
    /// Camera polar angle from the zenith, degrees.
    pub view_theta_deg: f64,
    /// Camera azimuth from +x, degrees.
    pub view_phi_deg: f64,
    pub projection: Projection,
}

impl Default for SceneConfig {
    /// The preview: a unit sphere seen orthographically from 20 degrees above the horizon,
    /// under the default sun and sky (sun 40 degrees high, 30 degrees to the camera's right).
    fn default() -> Self {
        Self {
            shape: Shape::default(),
            light: LightSpec::default(),
            view_theta_deg: 70.0,
            view_phi_deg: 0.0,
            projection: Projection::Orthographic,
        }
    }
}

impl SceneConfig {
    /// Builds the scene.
    pub fn build(&self) -> Result<Scene> {
        self.shape.validate()?;
        let camera = Camera::new(
            self.projection,
            self.view_theta_deg,
            self.view_phi_deg,
            self.shape.bounding_radius(),
        )?;
        Ok(Scene { shape: self.shape, camera, lighting: self.light.build()? })
    }
}

/// A built scene, ready to render.
#[derive(Clone, Debug)]
pub struct Scene {
    pub shape: Shape,
    pub camera: Camera,
    pub lighting: Lighting,
}
