//! The RGB BRDF of an isotropic RGL measurement (Dupuy & Jakob 2018, "An Adaptive
//! Parameterization for Efficient Material Acquisition and Rendering"), evaluated as the
//! authors' reference `powitacq` (`BRDF::eval`, `BRDF::pdf`, `BRDF::sample` in
//! `powitacq_rgb.inl`; Mitsuba's `measured` BSDF evaluates the same way):
//!
//! 1. the half vector `wm` of (wi, wo) and the angles of wi and wm, with theta mapped to
//!    `u = sqrt(theta / (pi/2))` and phi to `(phi + pi) / 2 pi` (wm's azimuth relative to wi's);
//! 2. `u_wm` is mapped back through the VNDF warp (the `vndf` table, interpolated over theta_i)
//!    to the unit square where the `rgb` table is sampled: `sample = vndf.invert(u_wm)`;
//! 3. `f_r cos(theta_o) = rgb(sample; theta_i) * ndf(u_wm) / (4 sigma(u_wi))`: the measured
//!    table, stored relative to the microfacet sampling density, times the NDF over four times
//!    the projected area `sigma` (the paper's factorisation; the reference's `BRDF::eval`).
//!
//! The reference returns `f_r cos(theta_o)` ([`RglBrdf::eval_cos`]). A MERL cell stands for both
//! orderings of its two directions (phi_d and phi_d + pi are folded together), and measured data
//! are not exactly reciprocal, so the cell needs a rule: [`RglBrdf::reciprocal`] takes the
//! cosine-weighted average of the two orderings, `(e(a, b) + e(b, a)) / (cos a + cos b)`, where
//! `e` is the reference's `f_r cos(theta_o)`. For a reciprocal BRDF this is exactly f_r; unlike
//! `e(a, b) / cos b` it never divides by the cosine of a grazing direction alone (where the
//! tables, interpolated across the horizon, make `e / cos` blow up), and it weights each ordering
//! by how well its outgoing direction is resolved. `experiments convert --report` measures what
//! the choice changes against the plain average of `e(a, b) / cos b` and `e(b, a) / cos a`.

use super::tensor::TensorFile;
use super::warp::Marginal2D;
use crate::error::{DataError, Result};
use std::f32::consts::PI;
use std::path::Path;

/// The RGB evaluator of one isotropic RGL measurement.
#[derive(Debug, Clone)]
pub struct RglBrdf {
    description: String,
    theta_i: Vec<f32>,
    ndf: Marginal2D,
    sigma: Marginal2D,
    vndf: Marginal2D,
    luminance: Marginal2D,
    rgb: Marginal2D,
}

/// `sqrt(theta / (pi/2))`: the square-root warp of polar angles.
#[inline]
fn theta2u(theta: f32) -> f32 {
    (theta * (2.0 / PI)).sqrt()
}

/// `(phi + pi) / 2 pi`.
#[inline]
fn phi2u(phi: f32) -> f32 {
    (phi + PI) / (2.0 * PI)
}

/// `acos(d.z)` computed robustly (the reference's `elevation`).
#[inline]
fn elevation(d: [f32; 3]) -> f32 {
    2.0 * (0.5 * (d[0] * d[0] + d[1] * d[1] + (d[2] - 1.0) * (d[2] - 1.0)).sqrt()).asin()
}

#[inline]
fn normalize(v: [f32; 3]) -> [f32; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

#[inline]
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The angles and warped coordinates the reference computes for a direction pair.
struct Query {
    /// (phi_i, theta_i): the parameters of the conditional tables.
    params: [f32; 2],
    u_wi: [f32; 2],
    u_wm: [f32; 2],
    wm: [f32; 3],
}

impl Query {
    fn new(wi: [f32; 3], wo: [f32; 3]) -> Self {
        let wm = normalize([wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]]);
        let (theta_i, phi_i) = (elevation(wi), wi[1].atan2(wi[0]));
        let (theta_m, phi_m) = (elevation(wm), wm[1].atan2(wm[0]));
        let mut u_wm = [theta2u(theta_m), phi2u(phi_m - phi_i)];
        u_wm[1] -= u_wm[1].floor();
        Self { params: [phi_i, theta_i], u_wi: [theta2u(theta_i), phi2u(phi_i)], u_wm, wm }
    }
}

impl RglBrdf {
    /// Reads an RGL `.bsdf` file; see [`RglBrdf::from_tensor`] for what is checked.
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        Self::from_tensor(&TensorFile::read(path)?)
    }

    /// Parses the bytes of an RGL `.bsdf` file; `path` names it in errors.
    pub fn parse(path: impl AsRef<Path>, bytes: &[u8]) -> Result<Self> {
        Self::from_tensor(&TensorFile::parse(path, bytes)?)
    }

    /// The evaluator of a tensor file: the fields and shapes the reference requires (`theta_i`,
    /// `phi_i`, `ndf`, `sigma`, `vndf`, `luminance`, `rgb` as f32, `description` as u8), every
    /// table finite, `sigma` positive, `ndf`, `vndf` and `luminance` non-negative with
    /// positive integrals, `theta_i` strictly increasing in [0, pi/2]. Anisotropic files (more
    /// than one `phi_i`) are refused. Errors name the file and the field.
    pub fn from_tensor(t: &TensorFile) -> Result<Self> {
        let path = t.path();
        let bad = |field: &str, problem: String| {
            DataError::format(path, format!("field {field:?}: {problem}"))
        };
        let description = t.require("description")?;
        if description.dtype() != super::tensor::Dtype::U8 || description.shape().len() != 1 {
            return Err(bad("description", "expected a 1-D u8 string".into()));
        }
        let description = String::from_utf8_lossy(description.bytes()).into_owned();
        let (_, phi_i) = t.f32_field("phi_i", 1)?;
        if phi_i.len() != 1 {
            return Err(bad(
                "phi_i",
                format!(
                    "{} incidence azimuths: an anisotropic measurement, not supported (only \
                     isotropic files, with one phi_i, are)",
                    phi_i.len()
                ),
            ));
        }
        let (_, theta_i) = t.f32_field("theta_i", 1)?;
        if theta_i.len() < 2
            || theta_i.windows(2).any(|w| w[0].partial_cmp(&w[1]) != Some(std::cmp::Ordering::Less))
            || theta_i[0] < 0.0
            || theta_i[theta_i.len() - 1] > PI / 2.0 + 1e-4
        {
            return Err(bad(
                "theta_i",
                format!("{theta_i:?}: expected at least 2 increasing angles in [0, pi/2]"),
            ));
        }
        let n_theta = theta_i.len();
        let table2 = |name: &str, positive: bool| -> Result<Marginal2D> {
            let (shape, v) = t.f32_field(name, 2)?;
            if let Some(i) = v.iter().position(|&x| if positive { x <= 0.0 } else { x < 0.0 }) {
                return Err(bad(
                    name,
                    format!(
                        "element {i} is {} (must be >= 0{})",
                        v[i],
                        if positive { ", non-zero" } else { "" }
                    ),
                ));
            }
            Marginal2D::new([shape[1], shape[0]], &v, vec![], false).map_err(|e| bad(name, e))
        };
        let ndf = table2("ndf", false)?;
        let sigma = table2("sigma", true)?;
        let conditional =
            |name: &str, rank: usize, extra: usize| -> Result<(Vec<usize>, Vec<f32>)> {
                let (shape, v) = t.f32_field(name, rank)?;
                if shape[0] != 1 || shape[1] != n_theta || (rank == 5 && shape[2] != extra) {
                    return Err(bad(
                        name,
                        format!(
                            "shape {shape:?}, expected [1, {n_theta}{}, rows, cols]",
                            if rank == 5 { ", 3" } else { "" }
                        ),
                    ));
                }
                Ok((shape.to_vec(), v))
            };
        let params = vec![phi_i.clone(), theta_i.clone()];
        let density = |name: &str| -> Result<Marginal2D> {
            let (shape, v) = conditional(name, 4, 0)?;
            if let Some(i) = v.iter().position(|&x| x < 0.0) {
                return Err(bad(name, format!("element {i} is {} (a density is >= 0)", v[i])));
            }
            Marginal2D::new([shape[3], shape[2]], &v, params.clone(), true)
                .map_err(|e| bad(name, e))
        };
        let vndf = density("vndf")?;
        let luminance = density("luminance")?;
        let (shape, v) = conditional("rgb", 5, 3)?;
        if [shape[3], shape[4]] != [luminance.size()[1], luminance.size()[0]] {
            return Err(bad("rgb", format!("shape {shape:?} does not match the luminance table")));
        }
        let rgb = Marginal2D::new(
            [shape[4], shape[3]],
            &v,
            vec![phi_i, theta_i.clone(), vec![0.0, 1.0, 2.0]],
            false,
        )
        .map_err(|e| bad("rgb", e))?;
        Ok(Self { description, theta_i, ndf, sigma, vndf, luminance, rgb })
    }

    /// The file's description (the material's name).
    pub fn description(&self) -> &str {
        &self.description
    }

    /// The incidence angles at which the material was measured (radians).
    pub fn theta_i(&self) -> &[f32] {
        &self.theta_i
    }

    /// The reference's value, `f_r(wi, wo) cos(theta_o)` in RGB (channels may be slightly
    /// negative where the measured spectrum is out of the RGB gamut); 0 below the horizon.
    pub fn eval_cos(&self, wi: [f32; 3], wo: [f32; 3]) -> [f32; 3] {
        if !(wi[2] > 0.0 && wo[2] > 0.0) {
            return [0.0; 3];
        }
        let q = Query::new(wi, wo);
        let (sample, _) = self.vndf.invert(q.u_wm, &q.params);
        self.rgb_at(&q, sample)
    }

    /// `rgb(sample) ndf(u_wm) / (4 sigma(u_wi))` for a query.
    fn rgb_at(&self, q: &Query, sample: [f32; 2]) -> [f32; 3] {
        let scale = self.ndf.eval(q.u_wm, &q.params) / (4.0 * self.sigma.eval(q.u_wi, &q.params));
        std::array::from_fn(|c| {
            self.rgb.eval(sample, &[q.params[0], q.params[1], c as f32]) * scale
        })
    }

    /// The BRDF (1/sr) of a MERL cell, from f64 directions: the cosine-weighted average of both
    /// orderings (see the module documentation), clamped at 0; 0 below the horizon.
    pub fn reciprocal(&self, a: [f64; 3], b: [f64; 3]) -> [f32; 3] {
        let (a, b) = (a.map(|v| v as f32), b.map(|v| v as f32));
        if !(a[2] > 0.0 && b[2] > 0.0) {
            return [0.0; 3];
        }
        let (ab, ba) = (self.eval_cos(a, b), self.eval_cos(b, a));
        let norm = a[2] + b[2];
        std::array::from_fn(|c| ((ab[c] + ba[c]) / norm).max(0.0))
    }

    /// The alternative rule measured against [`RglBrdf::reciprocal`]: the plain average of
    /// `e(a, b) / cos b` and `e(b, a) / cos a`, clamped at 0.
    pub fn mean_of_orderings(&self, a: [f64; 3], b: [f64; 3]) -> [f32; 3] {
        let (a, b) = (a.map(|v| v as f32), b.map(|v| v as f32));
        if !(a[2] > 0.0 && b[2] > 0.0) {
            return [0.0; 3];
        }
        let (ab, ba) = (self.eval_cos(a, b), self.eval_cos(b, a));
        std::array::from_fn(|c| (0.5 * (ab[c] / b[2] + ba[c] / a[2])).max(0.0))
    }

    /// The reference's sampling density of wo given wi (solid angle), as `BRDF::pdf`.
    pub fn pdf(&self, wi: [f32; 3], wo: [f32; 3]) -> f32 {
        if !(wi[2] > 0.0 && wo[2] > 0.0) {
            return 0.0;
        }
        let q = Query::new(wi, wo);
        let (sample, vndf_pdf) = self.vndf.invert(q.u_wm, &q.params);
        let lum_pdf = self.luminance.eval(sample, &q.params);
        vndf_pdf * lum_pdf / self.jacobian(&q, wi)
    }

    /// `|d u_wm / d wo|` of the reference: `2 pi^2 u sin(theta_m) 4 <wi, wm>`.
    fn jacobian(&self, q: &Query, wi: [f32; 3]) -> f32 {
        let sin_theta_m = (q.wm[0] * q.wm[0] + q.wm[1] * q.wm[1]).sqrt();
        (2.0 * PI * PI * q.u_wm[0] * sin_theta_m).max(1e-6) * 4.0 * dot(wi, q.wm)
    }

    /// Samples wo given wi from a uniform `u` in [0, 1)^2 as the reference's `BRDF::sample`:
    /// the luminance warp, then the VNDF warp. Returns wo and its density (solid angle), or
    /// `None` when wi or the sampled wo is at or below the horizon.
    pub fn sample(&self, u: [f32; 2], wi: [f32; 3]) -> Option<([f32; 3], f32)> {
        // NaN-safe: a NaN direction is not above the horizon.
        if wi[2].is_nan() || wi[2] <= 0.0 {
            return None;
        }
        let params = [wi[1].atan2(wi[0]), elevation(wi)];
        let (sample, lum_pdf) = self.luminance.sample([u[1], u[0]], &params);
        let (u_wm, ndf_pdf) = self.vndf.sample(sample, &params);
        let phi_m = (2.0 * u_wm[1] - 1.0) * PI + params[0];
        let theta_m = u_wm[0] * u_wm[0] * (PI / 2.0);
        let (sp, cp) = phi_m.sin_cos();
        let (st, ct) = theta_m.sin_cos();
        let wm = [cp * st, sp * st, ct];
        let k = 2.0 * dot(wm, wi);
        let wo = [wm[0] * k - wi[0], wm[1] * k - wi[1], wm[2] * k - wi[2]];
        if wo[2].is_nan() || wo[2] <= 0.0 {
            return None;
        }
        let jacobian = (2.0 * PI * PI * u_wm[0] * st).max(1e-6) * 4.0 * dot(wi, wm);
        Some((wo, ndf_pdf * lum_pdf / jacobian))
    }

    /// The VNDF warp at incidence `wi`: unit-square sample to half-vector coordinates u_wm
    /// (theta and relative-phi unit coordinates), and its inverse. Exposed for tests.
    pub fn vndf_warp(&self, sample: [f32; 2], theta_i: f32) -> [f32; 2] {
        self.vndf.sample(sample, &[0.0, theta_i]).0
    }

    /// The inverse of [`RglBrdf::vndf_warp`].
    pub fn vndf_unwarp(&self, u_wm: [f32; 2], theta_i: f32) -> [f32; 2] {
        self.vndf.invert(u_wm, &[0.0, theta_i]).0
    }

    /// The direction pair at which the `rgb` table's node (`theta_index`, row, col) is sampled:
    /// wi at `theta_i[theta_index]` (phi_i = 0) and wo mirrored about the half vector that the
    /// VNDF warp maps the node's position to. For tests of the evaluator against its own table.
    pub fn node_directions(
        &self,
        theta_index: usize,
        row: usize,
        col: usize,
    ) -> ([f32; 3], [f32; 3]) {
        let [nx, ny] = self.rgb.size();
        let pos = [col as f32 / (nx - 1) as f32, row as f32 / (ny - 1) as f32];
        let theta_i = self.theta_i[theta_index];
        let u_wm = self.vndf_warp(pos, theta_i);
        let wi = [theta_i.sin(), 0.0, theta_i.cos()];
        let phi_m = (2.0 * u_wm[1] - 1.0) * PI;
        let theta_m = u_wm[0] * u_wm[0] * (PI / 2.0);
        let wm = [phi_m.cos() * theta_m.sin(), phi_m.sin() * theta_m.sin(), theta_m.cos()];
        let k = 2.0 * dot(wm, wi);
        (wi, [wm[0] * k - wi[0], wm[1] * k - wi[1], wm[2] * k - wi[2]])
    }

    /// The factor `ndf(u_wm) / (4 sigma(u_wi))` that multiplies the `rgb` table at (wi, wo).
    pub fn scale(&self, wi: [f32; 3], wo: [f32; 3]) -> f32 {
        let q = Query::new(wi, wo);
        self.ndf.eval(q.u_wm, &q.params) / (4.0 * self.sigma.eval(q.u_wi, &q.params))
    }
}
