//! The 7 editable attributes of a BRDF (Hu et al. 2020, §5.1, eq. (6): diffuse albedo, specular
//! albedo, roughness, after Guo et al. 2018), defined through an analytic model, a Lambertian
//! term plus one GGX microfacet lobe (the renderer's [`Ggx`] with Schlick's Fresnel):
//!
//! `f(wi, wo) = diffuse / pi + D_alpha(h) G_alpha(wi, wo) F(wi . h) / (4 cos_i cos_o)`,
//! `F(c) = specular + (1 - specular) (1 - c)^5`.
//!
//! [`fit`] estimates them from a tabulated BRDF; [`AttributeMethod`] is the 7-number
//! representation as a harness method (decode = tabulate the analytic model).

mod fit;
mod method;
mod report;

pub use fit::{fit, AttributeFit, FitConfig};
pub use method::{AttributeCodec, AttributeMethod};
pub use report::{csv, markdown, summary, write_csv, AttributeRow};

use crate::error::{EvalError, Result};
use deepbrdf_data::merl::coords::HalfDiff;
use deepbrdf_data::merl::grid::{phi_d_of, theta_d_of, theta_h_of, valid_mask};
use deepbrdf_data::merl::{cell_coords, CELLS, INVALID_VALUE, VALUES};
use deepbrdf_data::MerlTable;
use deepbrdf_render::geometry::Vec3;
use deepbrdf_render::{Brdf, Ggx, Lambertian, Sum};
use rayon::prelude::*;
use std::f64::consts::PI;

/// Smallest roughness the model takes (the renderer's [`Ggx::new`] clamps below 1e-4; the MERL
/// grid's first theta_h step is 1.9e-4 rad, so sharper lobes are not resolved).
pub const MIN_ROUGHNESS: f64 = 1e-3;
/// Largest roughness (GGX alpha = 1: a lobe as wide as the hemisphere).
pub const MAX_ROUGHNESS: f64 = 1.0;

/// Names of the 7 values in [`Attributes::to_array`] order (CSV columns, error messages).
pub const ATTRIBUTE_NAMES: [&str; 7] =
    ["diffuse_r", "diffuse_g", "diffuse_b", "specular_r", "specular_g", "specular_b", "roughness"];

/// The 7 attributes of a material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attributes {
    /// Diffuse albedo per channel, in [0, 1]: the Lambertian term is `diffuse / pi`, so this is
    /// that term's directional albedo (the same at every incident angle).
    pub diffuse: [f64; 3],
    /// Specular albedo per channel, in [0, 1]: Schlick's `F0`, the lobe's reflectance at
    /// normal incidence. It is the lobe's directional albedo at normal incidence in the smooth
    /// limit (alpha -> 0, where masking vanishes and the reflection is the mirror direction);
    /// at larger alpha the lobe reflects somewhat less than that (GGX masking).
    pub specular: [f64; 3],
    /// Roughness: the GGX alpha of the lobe (Walter et al. 2007, eq. 33), in
    /// [[`MIN_ROUGHNESS`], [`MAX_ROUGHNESS`]]. The lobe's half-vector slopes have RMS width
    /// ~alpha; alpha = roughness^2 in Disney's parametrisation.
    pub roughness: f64,
}

impl Attributes {
    /// Checks the ranges (albedos in [0, 1], roughness in its range, all finite).
    pub fn validate(&self) -> Result<()> {
        for (name, v) in ATTRIBUTE_NAMES.iter().zip(self.to_array()) {
            let (lo, hi) =
                if *name == "roughness" { (MIN_ROUGHNESS, MAX_ROUGHNESS) } else { (0.0, 1.0) };
            if !v.is_finite() || v < lo || v > hi {
                return Err(EvalError::Invalid(format!(
                    "attribute {name} = {v} is outside [{lo}, {hi}]"
                )));
            }
        }
        Ok(())
    }

    /// The 7 values: diffuse RGB, specular RGB, roughness.
    pub fn to_array(&self) -> [f64; 7] {
        let (d, s) = (self.diffuse, self.specular);
        [d[0], d[1], d[2], s[0], s[1], s[2], self.roughness]
    }

    /// Attributes from 7 values in [`Attributes::to_array`] order, checked.
    pub fn from_slice(values: &[f64]) -> Result<Self> {
        if values.len() != 7 {
            return Err(EvalError::Invalid(format!(
                "7 attributes ({}) expected, got {}",
                ATTRIBUTE_NAMES.join(", "),
                values.len()
            )));
        }
        let a = Self {
            diffuse: [values[0], values[1], values[2]],
            specular: [values[3], values[4], values[5]],
            roughness: values[6],
        };
        a.validate()?;
        Ok(a)
    }

    /// The blend `(1 - t) self + t other` of two materials' attributes, as the latent blend of
    /// eq. (7) pairs them: the albedos linearly, the roughness in log space, as the regressor
    /// sees it.
    pub fn blend(&self, other: &Attributes, t: f64) -> Attributes {
        let mix = |x: f64, y: f64| (1.0 - t) * x + t * y;
        Attributes {
            diffuse: [0, 1, 2].map(|c| mix(self.diffuse[c], other.diffuse[c])),
            specular: [0, 1, 2].map(|c| mix(self.specular[c], other.specular[c])),
            roughness: mix(self.roughness.ln(), other.roughness.ln()).exp(),
        }
    }

    /// The analytic BRDF, for the renderer (sampled as a mixture of its two terms).
    pub fn brdf(&self) -> Sum<Lambertian, Ggx> {
        Sum::plastic(self.diffuse, self.roughness, self.specular)
    }

    /// The analytic BRDF tabulated on the MERL grid: each valid cell ([`valid_mask`]) gets the
    /// value at its sample angles with phi_h = 0 ([`deepbrdf_data::merl::grid`]), as the
    /// bundled tables are tabulated; invalid cells get [`INVALID_VALUE`].
    pub fn table(&self) -> MerlTable {
        let brdf = self.brdf();
        let mask = valid_mask();
        let rgb: Vec<[f32; 3]> = (0..CELLS)
            .into_par_iter()
            .map(|cell| match mask[cell] {
                true => {
                    let (wi, wo) = cell_directions(cell);
                    brdf.eval(wi, wo).map(|v| v as f32)
                }
                false => [INVALID_VALUE; 3],
            })
            .collect();
        let mut values = vec![INVALID_VALUE; VALUES];
        for (cell, v) in rgb.iter().enumerate() {
            for c in 0..3 {
                values[c * CELLS + cell] = v[c];
            }
        }
        MerlTable::from_values(values).expect("analytic values are finite")
    }
}

/// The direction pair (wi, wo) at which `cell` is sampled (its grid angles, phi_h = 0).
pub(crate) fn cell_directions(cell: usize) -> (Vec3, Vec3) {
    let (h, d, p) = cell_coords(cell);
    let angles =
        HalfDiff { theta_h: theta_h_of(h), phi_h: 0.0, theta_d: theta_d_of(d), phi_d: phi_d_of(p) };
    let (wi, wo) = angles.to_dirs();
    (Vec3::new(wi[0], wi[1], wi[2]), Vec3::new(wo[0], wo[1], wo[2]))
}

/// `1 / pi`, the Lambertian term per unit albedo.
const INV_PI: f64 = 1.0 / PI;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_blend_mixes_albedos_linearly_and_the_roughness_in_log_space() {
        let a = Attributes { diffuse: [0.2, 0.4, 0.6], specular: [0.0, 0.1, 0.2], roughness: 0.01 };
        let b = Attributes { diffuse: [0.6, 0.4, 0.2], specular: [0.2, 0.1, 0.0], roughness: 1.0 };
        let m = a.blend(&b, 0.5);
        for (x, y) in m.diffuse.iter().zip([0.4, 0.4, 0.4]) {
            assert!((x - y).abs() < 1e-12, "{m:?}");
        }
        for (x, y) in m.specular.iter().zip([0.1, 0.1, 0.1]) {
            assert!((x - y).abs() < 1e-12, "{m:?}");
        }
        // The geometric mean of 0.01 and 1.
        assert!((m.roughness - 0.1).abs() < 1e-12, "{m:?}");
        assert_eq!(a.blend(&b, 0.0).diffuse, a.diffuse);
    }

    #[test]
    fn attributes_round_trip_and_reject_out_of_range_values() {
        let a = Attributes { diffuse: [0.1, 0.2, 0.3], specular: [0.04, 0.5, 1.0], roughness: 0.2 };
        assert_eq!(Attributes::from_slice(&a.to_array()).unwrap(), a);
        let mut v = a.to_array();
        v[1] = 1.2;
        let e = Attributes::from_slice(&v).unwrap_err().to_string();
        assert!(e.contains("diffuse_g") && e.contains("1.2"), "{e}");
        v[1] = 0.2;
        v[6] = -0.1;
        let e = Attributes::from_slice(&v).unwrap_err().to_string();
        assert!(e.contains("roughness"), "{e}");
        v[6] = f64::NAN;
        assert!(Attributes::from_slice(&v).is_err());
        assert!(Attributes::from_slice(&v[..6]).unwrap_err().to_string().contains("got 6"));
    }

    #[test]
    fn table_matches_the_renderers_brdf_at_cell_angles() {
        let a = Attributes { diffuse: [0.3, 0.2, 0.1], specular: [0.9, 0.5, 0.2], roughness: 0.1 };
        let t = a.table();
        assert_eq!(t.mask(), valid_mask().to_vec());
        let brdf = a.brdf();
        for cell in (0..CELLS).step_by(9973).filter(|&c| valid_mask()[c]) {
            let (wi, wo) = cell_directions(cell);
            let f = brdf.eval(wi, wo);
            for c in 0..3 {
                let v = f64::from(t.values()[c * CELLS + cell]);
                assert!((v - f[c]).abs() <= 1e-6 * f[c].max(1.0), "cell {cell}: {v} vs {}", f[c]);
            }
        }
        // The diffuse floor: far from the peak the value is diffuse / pi plus a small lobe.
        let (h, d, p) = (80, 10, 90);
        let v = t.rgb(h, d, p);
        assert!(f64::from(v[0]) >= 0.3 * INV_PI && f64::from(v[0]) < 0.3 * INV_PI + 0.05, "{v:?}");
    }
}
