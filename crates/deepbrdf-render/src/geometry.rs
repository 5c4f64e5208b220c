//! Small 3D geometry for the renderer: vectors, rays and orthonormal shading frames.
//!
//! The world is z-up (the sky's zenith is +z). Shading happens in a local frame whose z axis is
//! the surface normal, the convention of the MERL lookups (`deepbrdf_data::merl::lookup`).

use std::ops::{Add, Mul, Neg, Sub};

/// A 3D vector (f64).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vec3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl Vec3 {
    /// The vector (x, y, z).
    #[inline]
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }

    /// The unit vector at polar angle `theta` from +z and azimuth `phi` from +x (radians).
    #[inline]
    pub fn from_spherical(theta: f64, phi: f64) -> Self {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        Self::new(st * cp, st * sp, ct)
    }

    #[inline]
    pub fn dot(self, o: Self) -> f64 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline]
    pub fn cross(self, o: Self) -> Self {
        Self::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }

    #[inline]
    pub fn length_squared(self) -> f64 {
        self.dot(self)
    }

    #[inline]
    pub fn length(self) -> f64 {
        self.length_squared().sqrt()
    }

    /// This vector scaled to unit length (unchanged if it is zero).
    #[inline]
    pub fn normalized(self) -> Self {
        let l = self.length();
        if l > 0.0 {
            self * (1.0 / l)
        } else {
            self
        }
    }

    /// Component-wise product.
    #[inline]
    pub fn mul_elem(self, o: Self) -> Self {
        Self::new(self.x * o.x, self.y * o.y, self.z * o.z)
    }

    /// Component-wise quotient.
    #[inline]
    pub fn div_elem(self, o: Self) -> Self {
        Self::new(self.x / o.x, self.y / o.y, self.z / o.z)
    }

    /// As an array `[x, y, z]`, the form of `deepbrdf_data`'s direction arguments.
    #[inline]
    pub fn to_array(self) -> [f64; 3] {
        [self.x, self.y, self.z]
    }

    /// Mirror reflection of `self` about the unit normal `n`: `2 (v.n) n - v`.
    #[inline]
    pub fn reflect(self, n: Self) -> Self {
        n * (2.0 * self.dot(n)) - self
    }
}

impl Add for Vec3 {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl Sub for Vec3 {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl Neg for Vec3 {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y, -self.z)
    }
}

impl Mul<f64> for Vec3 {
    type Output = Self;
    #[inline]
    fn mul(self, s: f64) -> Self {
        Self::new(self.x * s, self.y * s, self.z * s)
    }
}

/// A ray `origin + t * dir`, `dir` of unit length.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl Ray {
    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f64) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// An orthonormal frame (tangent, bitangent, normal).
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub t: Vec3,
    pub b: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// A frame around the unit normal `n`, by the branchless construction of Duff et al.,
    /// "Building an orthonormal basis, revisited" (JCGT 2017). Any tangent will do: every BRDF
    /// here is isotropic.
    #[inline]
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let t = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let bt = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { t, b: bt, n }
    }

    /// World vector `v` in this frame's coordinates (z along the normal).
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }

    /// Local vector `v` in world coordinates.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.t * v.x + self.b * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_invert() {
        for &(theta, phi) in
            &[(0.0, 0.0), (0.3, 1.0), (1.5, -2.0), (3.1, 0.4), (std::f64::consts::PI, 0.0)]
        {
            let n = Vec3::from_spherical(theta, phi);
            let f = Frame::from_normal(n);
            for (a, b) in [(f.t, f.b), (f.t, f.n), (f.b, f.n)] {
                assert!(a.dot(b).abs() < 1e-12);
            }
            for v in [f.t, f.b, f.n] {
                assert!((v.length() - 1.0).abs() < 1e-12);
            }
            assert!((f.to_local(n).z - 1.0).abs() < 1e-12);
            let v = Vec3::new(0.3, -0.2, 0.9);
            let back = f.to_world(f.to_local(v));
            assert!((back - v).length() < 1e-12);
        }
    }

    #[test]
    fn reflection_about_the_normal() {
        let n = Vec3::new(0.0, 0.0, 1.0);
        let v = Vec3::new(0.6, 0.0, 0.8);
        assert!((v.reflect(n) - Vec3::new(-0.6, 0.0, 0.8)).length() < 1e-15);
    }
}
