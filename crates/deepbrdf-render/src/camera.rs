//! Cameras looking at the origin from any viewpoint: orthographic or perspective.
//!
//! The viewpoint is given by spherical angles of the direction from the origin to the camera:
//! `theta` from the zenith (+z), `phi` counter-clockwise from +x. Image "up" is the projection of
//! +z (of +y when looking straight down or up); image "right" is `forward x up`. Pixel `(x, y)`
//! counts from the top-left corner.

use super::geometry::{Ray, Vec3};
use crate::error::{RenderError, Result};
use serde::{Deserialize, Serialize};

/// How the camera projects.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Projection {
    /// Parallel rays.
    Orthographic,
    /// A pinhole with the given full vertical field of view (degrees).
    Perspective { fov_deg: f64 },
}

/// A camera framing a sphere of radius `extent` around the origin.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    projection: Projection,
    /// Unit vector from the origin towards the camera.
    towards: Vec3,
    right: Vec3,
    up: Vec3,
    /// Half the image side at the origin (orthographic) or `tan(fov / 2)` (perspective).
    half: f64,
    /// Eye position (perspective) or the plane the parallel rays start from (orthographic).
    distance: f64,
}

/// Margin around the framed sphere, as a fraction of its radius.
const MARGIN: f64 = 0.04;

impl Camera {
    /// A camera at angles (`theta_deg`, `phi_deg`) that frames the sphere of radius `extent`
    /// around the origin with a small margin.
    pub fn new(projection: Projection, theta_deg: f64, phi_deg: f64, extent: f64) -> Result<Self> {
        if !(theta_deg.is_finite() && phi_deg.is_finite() && extent.is_finite() && extent > 0.0) {
            return Err(RenderError::Invalid(format!(
                "view ({theta_deg}, {phi_deg}) deg with extent {extent}: must be finite"
            )));
        }
        let towards = Vec3::from_spherical(theta_deg.to_radians(), phi_deg.to_radians());
        let forward = -towards;
        let up_ref = if forward.z.abs() > 1.0 - 1e-9 {
            Vec3::new(0.0, 1.0, 0.0)
        } else {
            Vec3::new(0.0, 0.0, 1.0)
        };
        let right = forward.cross(up_ref).normalized();
        let up = right.cross(forward);
        let framed = extent * (1.0 + MARGIN);
        let (half, distance) = match projection {
            Projection::Orthographic => (framed, 2.0 * framed + 1.0),
            Projection::Perspective { fov_deg } => {
                if !(fov_deg > 0.1 && fov_deg < 170.0) {
                    return Err(RenderError::Invalid(format!(
                        "field of view {fov_deg} deg not in (0.1, 170)"
                    )));
                }
                let half_angle = (fov_deg / 2.0).to_radians();
                (half_angle.tan(), framed / half_angle.sin())
            }
        };
        Ok(Self { projection, towards, right, up, half, distance })
    }

    /// Unit vector from the origin towards the camera.
    pub fn towards(&self) -> Vec3 {
        self.towards
    }

    /// Image-right and image-up unit vectors.
    pub fn axes(&self) -> (Vec3, Vec3) {
        (self.right, self.up)
    }

    /// The ray through image position `(sx, sy)` in [0,1)^2 (0,0 = top-left corner).
    #[inline]
    pub fn ray(&self, sx: f64, sy: f64) -> Ray {
        let (x, y) = ((2.0 * sx - 1.0) * self.half, (1.0 - 2.0 * sy) * self.half);
        match self.projection {
            Projection::Orthographic => Ray {
                origin: self.towards * self.distance + self.right * x + self.up * y,
                dir: -self.towards,
            },
            Projection::Perspective { .. } => Ray {
                origin: self.towards * self.distance,
                dir: (-self.towards + self.right * x + self.up * y).normalized(),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_on_the_x_axis_sees_y_right_and_z_up() {
        let cam = Camera::new(Projection::Orthographic, 90.0, 0.0, 1.0).unwrap();
        let (r, u) = cam.axes();
        assert!((r - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-12);
        assert!((u - Vec3::new(0.0, 0.0, 1.0)).length() < 1e-12);
        let centre = cam.ray(0.5, 0.5);
        assert!((centre.dir - Vec3::new(-1.0, 0.0, 0.0)).length() < 1e-12);
        assert!(centre.origin.y.abs() < 1e-12 && centre.origin.z.abs() < 1e-12);
        // Top-left corner: left (-y) and up (+z), at the framed half-size.
        let corner = cam.ray(0.0, 0.0);
        assert!((corner.origin.y + 1.0 + MARGIN).abs() < 1e-12);
        assert!((corner.origin.z - 1.0 - MARGIN).abs() < 1e-12);
    }

    #[test]
    fn perspective_frames_the_bounding_sphere() {
        for (theta, phi) in [(0.0, 0.0), (60.0, 30.0), (180.0, 0.0), (90.0, -120.0)] {
            let cam =
                Camera::new(Projection::Perspective { fov_deg: 30.0 }, theta, phi, 1.0).unwrap();
            // Rays through the image centre's edges are tangent to a sphere of radius 1 + margin.
            for (sx, sy) in [(0.0, 0.5), (1.0, 0.5), (0.5, 0.0), (0.5, 1.0)] {
                let ray = cam.ray(sx, sy);
                let closest = ray.at(-ray.origin.dot(ray.dir));
                assert!((closest.length() - (1.0 + MARGIN)).abs() < 1e-9, "{theta} {phi}");
            }
            let centre = cam.ray(0.5, 0.5);
            assert!(centre.at(-centre.origin.dot(centre.dir)).length() < 1e-9);
        }
        assert!(Camera::new(Projection::Perspective { fov_deg: 0.0 }, 0.0, 0.0, 1.0).is_err());
        assert!(Camera::new(Projection::Orthographic, f64::NAN, 0.0, 1.0).is_err());
    }
}
