//! Analytic shapes to render materials on: a sphere (the default preview), a flat square, and
//! shapes of varied curvature for the recovery training set (§5.2): a torus (saddle regions of
//! negative Gaussian curvature), an ellipsoid (anisotropic curvature) and a capped cylinder
//! (one zero principal curvature, flat caps). All are centred at the origin, z up, and fit in a
//! sphere of radius about 1.

use super::geometry::{Ray, Vec3};
use crate::error::{RenderError, Result};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Rays start this far off a surface to avoid hitting it again (shadow rays).
const EPSILON: f64 = 1e-7;

/// A shape.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Shape {
    /// Sphere of radius `radius`.
    Sphere { radius: f64 },
    /// Square `[-half, half]^2` in the plane z = 0, seen from either side.
    Plane { half: f64 },
    /// Torus around the z axis: distance `major` from the axis to the tube's centre, tube radius
    /// `minor`.
    Torus { major: f64, minor: f64 },
    /// Ellipsoid with semi-axes `radii`.
    Ellipsoid { radii: [f64; 3] },
    /// Cylinder around the z axis of radius `radius`, `|z| <= half_height`, with flat caps.
    Cylinder { radius: f64, half_height: f64 },
}

/// A ray's first intersection with a shape.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Ray parameter.
    pub t: f64,
    /// Point.
    pub point: Vec3,
    /// Unit normal, facing the ray's origin side for the (two-sided) plane, outward otherwise.
    pub normal: Vec3,
}

/// The names the command line accepts, with the default shape of each.
pub const SHAPE_NAMES: [&str; 5] = ["sphere", "plane", "torus", "ellipsoid", "cylinder"];

impl Default for Shape {
    fn default() -> Self {
        Self::Sphere { radius: 1.0 }
    }
}

impl FromStr for Shape {
    type Err = RenderError;
    /// The default shape of a name in [`SHAPE_NAMES`].
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s {
            "sphere" => Self::Sphere { radius: 1.0 },
            "plane" => Self::Plane { half: 1.0 },
            "torus" => Self::Torus { major: 0.7, minor: 0.3 },
            "ellipsoid" => Self::Ellipsoid { radii: [0.75, 1.0, 0.55] },
            "cylinder" => Self::Cylinder { radius: 0.55, half_height: 0.8 },
            _ => {
                return Err(RenderError::Invalid(format!(
                    "unknown shape '{s}' (expected one of {})",
                    SHAPE_NAMES.join(", ")
                )))
            }
        })
    }
}

impl fmt::Display for Shape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Smallest root of `a t^2 + 2 b t + c = 0` above `t_min`, if any (numerically stable form).
#[inline]
fn quadratic_first(a: f64, b: f64, c: f64, t_min: f64) -> Option<f64> {
    let disc = b * b - a * c;
    if disc < 0.0 || a == 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    let q = -(b + sq.copysign(b));
    let (r0, r1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
    let (t0, t1) = if r0 < r1 { (r0, r1) } else { (r1, r0) };
    if t0 > t_min {
        Some(t0)
    } else if t1 > t_min {
        Some(t1)
    } else {
        None
    }
}

impl Shape {
    /// The shape's name, as in [`SHAPE_NAMES`].
    pub fn name(&self) -> &'static str {
        match self {
            Self::Sphere { .. } => "sphere",
            Self::Plane { .. } => "plane",
            Self::Torus { .. } => "torus",
            Self::Ellipsoid { .. } => "ellipsoid",
            Self::Cylinder { .. } => "cylinder",
        }
    }

    /// Checks the dimensions are positive and finite.
    pub fn validate(&self) -> Result<()> {
        let dims: Vec<f64> = match *self {
            Self::Sphere { radius } => vec![radius],
            Self::Plane { half } => vec![half],
            Self::Torus { major, minor } => vec![major, minor, major - minor],
            Self::Ellipsoid { radii } => radii.to_vec(),
            Self::Cylinder { radius, half_height } => vec![radius, half_height],
        };
        if dims.iter().all(|d| d.is_finite() && *d > 0.0) {
            Ok(())
        } else {
            Err(RenderError::Invalid(format!(
                "{self:?}: dimensions must be positive and finite (torus: major > minor)"
            )))
        }
    }

    /// Radius of a sphere about the origin containing the shape (for framing).
    pub fn bounding_radius(&self) -> f64 {
        match *self {
            Self::Sphere { radius } => radius,
            Self::Plane { half } => half * std::f64::consts::SQRT_2,
            Self::Torus { major, minor } => major + minor,
            Self::Ellipsoid { radii } => radii[0].max(radii[1]).max(radii[2]),
            Self::Cylinder { radius, half_height } => radius.hypot(half_height),
        }
    }

    /// Whether the shape can shadow itself (only then do shading points need shadow rays).
    pub fn self_shadows(&self) -> bool {
        matches!(self, Self::Torus { .. })
    }

    /// The first intersection of `ray` (unit direction) beyond `t_min`.
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, t_min: f64) -> Option<Hit> {
        let (o, d) = (ray.origin, ray.dir);
        match *self {
            Self::Sphere { radius } => {
                // |d| = 1: t = -b -/+ sqrt(b^2 - c), no division.
                let b = o.dot(d);
                let disc = b * b - (o.length_squared() - radius * radius);
                if disc < 0.0 {
                    return None;
                }
                let sq = disc.sqrt();
                let t = if -b - sq > t_min {
                    -b - sq
                } else if -b + sq > t_min {
                    -b + sq
                } else {
                    return None;
                };
                let p = ray.at(t);
                Some(Hit { t, point: p, normal: p * (1.0 / radius) })
            }
            Self::Plane { half } => {
                if d.z == 0.0 {
                    return None;
                }
                let t = -o.z / d.z;
                let p = ray.at(t);
                if t <= t_min || p.x.abs() > half || p.y.abs() > half {
                    return None;
                }
                let n = Vec3::new(0.0, 0.0, if d.z < 0.0 { 1.0 } else { -1.0 });
                Some(Hit { t, point: Vec3::new(p.x, p.y, 0.0), normal: n })
            }
            Self::Ellipsoid { radii } => {
                let r = Vec3::new(radii[0], radii[1], radii[2]);
                let (os, ds) = (o.div_elem(r), d.div_elem(r));
                let t = quadratic_first(
                    ds.length_squared(),
                    os.dot(ds),
                    os.length_squared() - 1.0,
                    t_min,
                )?;
                let p = ray.at(t);
                let n = p.div_elem(r.mul_elem(r)).normalized();
                Some(Hit { t, point: p, normal: n })
            }
            Self::Cylinder { radius, half_height } => cylinder_hit(ray, radius, half_height, t_min),
            Self::Torus { major, minor } => torus_hit(ray, major, minor, t_min),
        }
    }

    /// Whether anything of the shape lies along `dir` from `point` (a shading point on it).
    #[inline]
    pub fn occludes(&self, point: Vec3, normal: Vec3, dir: Vec3) -> bool {
        if !self.self_shadows() {
            return false;
        }
        let ray = Ray { origin: point + normal * (EPSILON * 10.0), dir };
        self.intersect(&ray, EPSILON).is_some()
    }
}

#[inline(never)]
fn cylinder_hit(ray: &Ray, radius: f64, half_height: f64, t_min: f64) -> Option<Hit> {
    let (o, d) = (ray.origin, ray.dir);
    let mut best: Option<Hit> = None;
    let mut consider = |t: f64, normal: Vec3, p: Vec3| {
        if t > t_min && best.is_none_or(|b| t < b.t) {
            best = Some(Hit { t, point: p, normal });
        }
    };
    // Side: x^2 + y^2 = radius^2 with |z| <= half_height; both roots, since the near one may
    // miss the height range.
    let a = d.x * d.x + d.y * d.y;
    if a > 0.0 {
        let b = o.x * d.x + o.y * d.y;
        let c = o.x * o.x + o.y * o.y - radius * radius;
        let disc = b * b - a * c;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            for t in [(-b - sq) / a, (-b + sq) / a] {
                let p = ray.at(t);
                if p.z.abs() <= half_height {
                    consider(t, Vec3::new(p.x / radius, p.y / radius, 0.0), p);
                }
            }
        }
    }
    // Caps.
    if d.z != 0.0 {
        for z in [-half_height, half_height] {
            let t = (z - o.z) / d.z;
            let p = ray.at(t);
            if p.x * p.x + p.y * p.y <= radius * radius {
                consider(t, Vec3::new(0.0, 0.0, z.signum()), p);
            }
        }
    }
    best
}

/// Real roots of the monic cubic `t^3 + a t^2 + b t + c` (Numerical Recipes, §5.6: the
/// trigonometric form for three real roots, Cardano's otherwise).
fn cubic_roots(a: f64, b: f64, c: f64) -> ([f64; 3], usize) {
    let q = (a * a - 3.0 * b) / 9.0;
    let r = (2.0 * a * a * a - 9.0 * a * b + 27.0 * c) / 54.0;
    let q3 = q * q * q;
    if r * r < q3 {
        let theta = (r / q3.sqrt()).clamp(-1.0, 1.0).acos();
        let s = -2.0 * q.sqrt();
        let tau = 2.0 * std::f64::consts::PI;
        (
            [
                s * (theta / 3.0).cos() - a / 3.0,
                s * ((theta + tau) / 3.0).cos() - a / 3.0,
                s * ((theta - tau) / 3.0).cos() - a / 3.0,
            ],
            3,
        )
    } else {
        let big = -r.signum() * (r.abs() + (r * r - q3).sqrt()).cbrt();
        let small = if big != 0.0 { q / big } else { 0.0 };
        ([big + small - a / 3.0, 0.0, 0.0], 1)
    }
}

/// Intersection with the torus `(|p|^2 + R^2 - r^2)^2 = 4 R^2 (x^2 + y^2)`, a quartic `f(t)`
/// along the ray. The real roots of the cubic `f'(t)` split the ray's span inside the bounding
/// sphere into pieces where `f` is monotone, each holding at most one root: the first piece whose
/// ends differ in sign holds the first hit, refined by bisection.
#[inline(never)]
fn torus_hit(ray: &Ray, major: f64, minor: f64, t_min: f64) -> Option<Hit> {
    let (o, d) = (ray.origin, ray.dir);
    let bound = major + minor;
    // Span inside the bounding sphere.
    let b = o.dot(d);
    let c = o.length_squared() - bound * bound;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    // Start a little outside the bounding sphere: it touches the torus along its equator.
    let (t0, t1) = ((-b - sq - 1e-6).max(t_min), -b + sq);
    if t1 <= t0 {
        return None;
    }
    // Quartic coefficients (|d| = 1): with k = t^2 + 2 b t + (|o|^2 + R^2 - r^2),
    // f(t) = k^2 - 4 R^2 ((ox + t dx)^2 + (oy + t dy)^2) = t^4 + c3 t^3 + c2 t^2 + c1 t + c0.
    let r2 = major * major;
    let e = o.length_squared() + r2 - minor * minor;
    let bb = 2.0 * b;
    let c3 = 2.0 * bb;
    let c2 = bb * bb + 2.0 * e - 4.0 * r2 * (d.x * d.x + d.y * d.y);
    let c1 = 2.0 * bb * e - 8.0 * r2 * (o.x * d.x + o.y * d.y);
    let c0 = e * e - 4.0 * r2 * (o.x * o.x + o.y * o.y);
    let f = |t: f64| (((t + c3) * t + c2) * t + c1) * t + c0;
    // f'(t) / 4 = t^3 + (3/4) c3 t^2 + (1/2) c2 t + (1/4) c1.
    let (crit, n_crit) = cubic_roots(0.75 * c3, 0.5 * c2, 0.25 * c1);
    let mut ends = [t0, t1, t1, t1, t1];
    let mut m = 1;
    for &t in &crit[..n_crit] {
        if t > t0 && t < t1 {
            ends[m] = t;
            m += 1;
        }
    }
    ends[m] = t1;
    ends[1..m].sort_by(f64::total_cmp);
    for w in ends[..=m].windows(2) {
        let (mut lo, mut hi) = (w[0], w[1]);
        let flo = f(lo);
        if (flo > 0.0) == (f(hi) > 0.0) {
            continue;
        }
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if (f(mid) > 0.0) == (flo > 0.0) {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo < 1e-13 {
                break;
            }
        }
        let t = 0.5 * (lo + hi);
        let p = ray.at(t);
        let ring = Vec3::new(p.x, p.y, 0.0).normalized() * major;
        return Some(Hit { t, point: p, normal: (p - ring).normalized() });
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn implicit(shape: &Shape, p: Vec3) -> f64 {
        match *shape {
            Shape::Sphere { radius } => p.length() - radius,
            Shape::Plane { .. } => p.z,
            Shape::Torus { major, minor } => {
                let q = (p.x.hypot(p.y) - major).hypot(p.z);
                q - minor
            }
            Shape::Ellipsoid { radii } => {
                (p.x / radii[0]).powi(2) + (p.y / radii[1]).powi(2) + (p.z / radii[2]).powi(2) - 1.0
            }
            Shape::Cylinder { radius, half_height } => {
                (p.x.hypot(p.y) - radius).max(p.z.abs() - half_height)
            }
        }
    }

    #[test]
    fn hits_lie_on_the_surface_with_unit_normals() {
        for name in SHAPE_NAMES {
            let shape: Shape = name.parse().unwrap();
            shape.validate().unwrap();
            let mut hits = 0;
            for i in 0..40 {
                for j in 0..40 {
                    let origin = Vec3::new(3.0, -2.0 + 0.1 * i as f64, -2.0 + 0.1 * j as f64);
                    let target = Vec3::new(0.0, -1.0 + 0.05 * j as f64, -1.0 + 0.05 * i as f64);
                    let ray = Ray { origin, dir: (target - origin).normalized() };
                    if let Some(h) = shape.intersect(&ray, 0.0) {
                        hits += 1;
                        assert!(implicit(&shape, h.point).abs() < 1e-6, "{name} {h:?}");
                        assert!((h.normal.length() - 1.0).abs() < 1e-9, "{name} {h:?}");
                        assert!(
                            h.normal.dot(ray.dir) < 1e-9,
                            "{name}: normal faces away from the ray {ray:?} {h:?}"
                        );
                        assert!(h.point.length() <= shape.bounding_radius() + 1e-9);
                    }
                }
            }
            assert!(hits > 100, "{name}: {hits} hits");
        }
    }

    #[test]
    fn first_hits_along_an_axis() {
        let ray = Ray { origin: Vec3::new(5.0, 0.0, 0.0), dir: Vec3::new(-1.0, 0.0, 0.0) };
        let t = |name: &str| name.parse::<Shape>().unwrap().intersect(&ray, 0.0).map(|h| h.t);
        assert!((t("sphere").unwrap() - 4.0).abs() < 1e-12);
        assert!((t("torus").unwrap() - 4.0).abs() < 1e-9); // outer equator at R + r = 1
        assert!((t("ellipsoid").unwrap() - 4.25).abs() < 1e-12);
        assert!((t("cylinder").unwrap() - 4.45).abs() < 1e-12);
        assert!(t("plane").is_none()); // parallel to the plane
                                       // Down the torus's axis: through the hole.
        let down = Ray { origin: Vec3::new(0.0, 0.0, 5.0), dir: Vec3::new(0.0, 0.0, -1.0) };
        assert!("torus".parse::<Shape>().unwrap().intersect(&down, 0.0).is_none());
        // The torus shadows itself across the hole.
        let torus: Shape = "torus".parse().unwrap();
        assert!(torus.occludes(
            Vec3::new(-0.4, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0)
        ));
        assert!(!torus.occludes(
            Vec3::new(0.7, 0.0, 0.3),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 0.0, 1.0)
        ));
    }

    #[test]
    fn cubic_roots_are_roots() {
        // (t - 1)(t + 2)(t - 3) = t^3 - 2 t^2 - 5 t + 6.
        let (r, n) = cubic_roots(-2.0, -5.0, 6.0);
        let mut r = r[..n].to_vec();
        r.sort_by(f64::total_cmp);
        assert_eq!(n, 3);
        for (a, b) in r.iter().zip([-2.0, 1.0, 3.0]) {
            assert!((a - b).abs() < 1e-12, "{r:?}");
        }
        // t^3 + t + 1: one real root near -0.6823.
        let (r, n) = cubic_roots(0.0, 1.0, 1.0);
        assert_eq!(n, 1);
        assert!((r[0] + 0.682_327_803_828_019_3).abs() < 1e-12);
    }

    #[test]
    fn rejects_unknown_names_and_bad_dimensions() {
        assert!("teapot".parse::<Shape>().is_err());
        assert!(Shape::Torus { major: 0.2, minor: 0.3 }.validate().is_err());
        assert!(Shape::Sphere { radius: f64::NAN }.validate().is_err());
    }
}
