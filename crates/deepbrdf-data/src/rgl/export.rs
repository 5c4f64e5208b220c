//! Exporting a MERL table as an isotropic RGB tensor file of the RGL format (Dupuy & Jakob 2018,
//! "An Adaptive Parameterization for Efficient Material Acquisition and Rendering"), the
//! measured-material format of Mitsuba 3 (`measured`) and pbrt-v4 (`measured`), built as the
//! paper builds it from a measurement:
//!
//! 1. the microfacet distribution from the retro-reflection `f(w, w)` by power iteration, and
//!    its projected area `sigma` ([`super::microfacet`]), tabulated over `u = sqrt(theta / (pi/2))`
//!    (fields `ndf` and `sigma`, two identical azimuth rows: the material is isotropic);
//! 2. incidence angles `theta_i` spaced uniformly in `sigma`, as in the RGL database's files;
//! 3. per incidence angle, the VNDF `D(m) <wi, m>+ / sigma(wi)` as a density over the unit square
//!    of `(u(theta_m), (phi_m - phi_i + pi) / 2 pi)` (field `vndf`, times the Jacobian
//!    `2 pi^2 u sin(theta_m)` of that square, each slice summing to 1 as in the database);
//! 4. the `rgb` table: at the nodes of a regular grid over the square that the VNDF warp maps
//!    to half vectors, `f_r(wi, wo) cos(theta_o) 4 sigma(wi) / D(m)`, with `wo` the mirror of
//!    `wi` about the half vector `m`: the quantity the readers multiply by `D / (4 sigma)`
//!    (`powitacq`'s `BRDF::eval`, Mitsuba's `Measured::eval`, `jacobian = 1`). `D` and `sigma`
//!    are the values the readers interpolate from the written tables, so the readers reproduce
//!    `f_r cos(theta_o)` exactly at every node; nodes whose `wo` is below the horizon hold 0 (as
//!    the database's files do) and are unset in `valid` (one bit per node, most significant
//!    bit first; no reader uses it);
//! 5. `luminance`: the Rec. 709 luminance of `rgb` (clamped at 0), the density the readers
//!    sample before the VNDF warp; a slice with no positive value is uniform.
//!
//! The table is evaluated as the renderer evaluates it ([`MerlTable::lookup_interpolated`],
//! clamped at 0). Only isotropic materials can be written: a MERL table has no azimuth of
//! incidence.

use super::microfacet::{incidence_angles, node_theta, retrieve};
use super::tensor::{Field, TensorFile};
use super::warp::Marginal2D;
use crate::error::{DataError, Result};
use crate::merl::grid::{cell_coords, cell_is_valid, CELLS};
use crate::MerlTable;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::PathBuf;

/// Rec. 709 luminance of linear RGB (the weights of the RGL files' `luminance` field).
pub fn luminance(rgb: [f64; 3]) -> f64 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// Resolutions of the written parameterization. The defaults (64 incidence angles, 128-node NDF
/// and projected area, 32 x 32 VNDF, 160 x 160 RGB samples per incidence angle) are finer than
/// the RGL database's isotropic files (8, 128, 128 x 128, 32 x 32): a file resampled from a
/// table needs them to reflect as much light as the table at grazing angles (docs/data.md
/// measures both).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExportResolution {
    /// Incidence angles (`theta_i`), at least 2.
    pub theta_i: usize,
    /// Nodes of the `ndf` and `sigma` tables, at least 2.
    pub ndf: usize,
    /// Side of each `vndf` slice, at least 2.
    pub vndf: usize,
    /// Side of each `rgb` and `luminance` slice, at least 2.
    pub rgb: usize,
}

impl Default for ExportResolution {
    fn default() -> Self {
        Self { theta_i: 64, ndf: 128, vndf: 32, rgb: 160 }
    }
}

impl ExportResolution {
    /// The resolutions of the RGL database's isotropic files.
    pub const RGL_DATABASE: Self = Self { theta_i: 8, ndf: 128, vndf: 128, rgb: 32 };

    /// Checks every resolution is in `2..=max` (the upper bounds keep the file under 1 GB).
    pub fn validate(&self) -> Result<()> {
        for (name, value, max) in [
            ("theta_i", self.theta_i, 90),
            ("ndf", self.ndf, 4096),
            ("vndf", self.vndf, 1024),
            ("rgb", self.rgb, 512),
        ] {
            if !(2..=max).contains(&value) {
                return Err(DataError::Invalid(format!(
                    "{name} resolution {value} must be in 2..={max}"
                )));
            }
        }
        Ok(())
    }
}

/// Checks that `table` can be exported: at least one valid cell, and no cell whose channels
/// disagree on validity (MERL marks a missing cell by making all three negative; one negative
/// channel beside measured ones is a damaged table). NaN cannot occur in a [`MerlTable`].
fn check_table(table: &MerlTable) -> Result<()> {
    let v = table.values();
    let mut valid = 0usize;
    for cell in 0..CELLS {
        let negative = [v[cell], v[CELLS + cell], v[2 * CELLS + cell]].map(|x| x < 0.0);
        if negative.iter().all(|&n| !n) {
            valid += 1;
        } else if negative.iter().any(|&n| !n) {
            let (i, j, k) = cell_coords(cell);
            let geometric = if cell_is_valid(i, j, k) { "" } else { " (below the horizon)" };
            return Err(DataError::Invalid(format!(
                "cell (theta_h {i}, theta_d {j}, phi_d {k}){geometric} has negative values in \
                 some channels and not others: {:?}",
                [v[cell], v[CELLS + cell], v[2 * CELLS + cell]]
            )));
        }
    }
    if valid == 0 {
        return Err(DataError::Invalid(
            "every cell is invalid (negative): nothing to export".into(),
        ));
    }
    Ok(())
}

/// Share of the uniform density in each `vndf` slice. The readers only use the VNDF table as the
/// warp from the unit square, where `rgb` is interpolated, to half vectors (and sample by it with
/// its own density), so any positive density is exact at the nodes. The visible normal density
/// alone vanishes towards the normal (the `u sin(theta_m)` area factor) and, at grazing
/// incidence, towards half vectors facing away: there one row or column of `rgb` nodes spans a
/// wide range of half vectors, across the horizon, and bilinear interpolation there loses the
/// table. The uniform share bounds that stretch (docs/data.md measures it).
const UNIFORM_WARP_SHARE: f64 = 0.5;

/// How far above the horizon (radians) the slice of incidence angle pi/2 reads the table.
const GRAZING_MARGIN: f64 = 1e-4;

/// A unit direction at polar angle `theta` and azimuth `phi`.
fn direction(theta: f64, phi: f64) -> [f64; 3] {
    crate::merl::coords::direction(theta, phi)
}

/// The table's RGB BRDF at (wi, wo) as the renderer reads it (interpolated, clamped at 0).
fn brdf(table: &MerlTable, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
    table.lookup_interpolated(wi, wo).map(|v| f64::from(v.max(0.0)))
}

/// The tensor file of `table`, named `description`, at `resolution`; `path` is where it will be
/// written (and what errors name). Errors: a table [`check_table`] refuses, a retro-reflection
/// from which no microfacet distribution can be retrieved, a resolution out of range.
pub fn export(
    table: &MerlTable,
    description: &str,
    resolution: &ExportResolution,
    path: impl Into<PathBuf>,
) -> Result<TensorFile> {
    let path = path.into();
    resolution.validate()?;
    check_table(table)?;
    let bad = |problem: String| DataError::Invalid(problem);
    let n = resolution.ndf;
    let retro: Vec<f64> = (0..n)
        .map(|j| {
            let w = direction(node_theta(j, n), 0.0);
            luminance(brdf(table, w, w))
        })
        .collect();
    let micro = retrieve(&retro).map_err(|e| bad(format!("microfacet distribution: {e}")))?;
    let ndf_f32: Vec<f32> = micro.ndf.iter().chain(&micro.ndf).map(|&v| v as f32).collect();
    let sigma_f32: Vec<f32> = micro.sigma.iter().chain(&micro.sigma).map(|&v| v as f32).collect();
    // The interpolants the readers build from these two fields.
    let ndf = Marginal2D::new([n, 2], &ndf_f32, vec![], false).map_err(&bad)?;
    let sigma = Marginal2D::new([n, 2], &sigma_f32, vec![], false).map_err(&bad)?;
    let theta_i: Vec<f32> =
        incidence_angles(&micro.sigma, resolution.theta_i).iter().map(|&t| t as f32).collect();

    let vndf_data = vndf_table(&ndf, &theta_i, resolution.vndf);
    let vndf = Marginal2D::new(
        [resolution.vndf, resolution.vndf],
        &vndf_data,
        vec![vec![0.0], theta_i.clone()],
        true,
    )
    .map_err(|e| bad(format!("VNDF: {e}")))?;
    let samples = Samples { table, ndf: &ndf, sigma: &sigma, vndf: &vndf, side: resolution.rgb };
    let slices: Vec<Slice> = theta_i.par_iter().map(|&t| samples.slice(t)).collect();

    let (m, v, t) = (resolution.rgb, resolution.vndf, theta_i.len());
    let mut rgb = Vec::with_capacity(t * 3 * m * m);
    let mut lum = Vec::with_capacity(t * m * m);
    let mut valid = vec![0u8; (t * m * m).div_ceil(8)];
    for (k, s) in slices.iter().enumerate() {
        rgb.extend(s.rgb.iter().copied());
        lum.extend(s.luminance.iter().copied());
        for (i, &ok) in s.valid.iter().enumerate() {
            if ok {
                let bit = k * m * m + i;
                valid[bit / 8] |= 0x80 >> (bit % 8);
            }
        }
    }
    if let Some(i) = rgb.iter().chain(&lum).position(|x| !x.is_finite()) {
        return Err(bad(format!("sample {i} of the RGB or luminance table is not finite")));
    }
    let fields = vec![
        Field::from_u32("version", &[2], &[1, 0])?,
        Field::from_u8("description", &[description.len()], description.as_bytes())?,
        Field::from_f32("phi_i", &[1], &[0.0])?,
        Field::from_f32("theta_i", &[t], &theta_i)?,
        Field::from_f32("sigma", &[2, n], &sigma_f32)?,
        Field::from_f32("ndf", &[2, n], &ndf_f32)?,
        Field::from_f32("vndf", &[1, t, v, v], &vndf_data)?,
        Field::from_f32("luminance", &[1, t, m, m], &lum)?,
        Field::from_f32("rgb", &[1, t, 3, m, m], &rgb)?,
        Field::from_u8("jacobian", &[1], &[1])?,
        Field::from_u8("valid", &[valid.len()], &valid)?,
    ];
    TensorFile::from_fields(path, fields)
}

/// The `vndf` field: per incidence angle, on a `side x side` grid of (relative azimuth rows, `u`
/// columns), the visible normal density `D(m) <wi, m>+ u sin(theta_m)` scaled to sum to 1, mixed
/// with the uniform density ([`UNIFORM_WARP_SHARE`]).
fn vndf_table(ndf: &Marginal2D, theta_i: &[f32], side: usize) -> Vec<f32> {
    let step = 1.0 / (side - 1) as f64;
    theta_i
        .par_iter()
        .flat_map_iter(|&t| {
            let wi = direction(f64::from(t), 0.0);
            let mut slice: Vec<f64> = (0..side * side)
                .map(|i| {
                    let (row, col) = (i / side, i % side);
                    let u = col as f64 * step;
                    let theta_m = u * u * FRAC_PI_2;
                    let phi_m = (2.0 * row as f64 * step - 1.0) * PI;
                    let m = direction(theta_m, phi_m);
                    let cos = (wi[0] * m[0] + wi[1] * m[1] + wi[2] * m[2]).max(0.0);
                    let d = f64::from(ndf.eval([u as f32, 0.5], &[]));
                    d * cos * u * theta_m.sin()
                })
                .collect();
            let sum: f64 = slice.iter().sum();
            let uniform = UNIFORM_WARP_SHARE / (side * side) as f64;
            slice.iter_mut().for_each(|v| *v = (1.0 - UNIFORM_WARP_SHARE) * *v / sum + uniform);
            slice.into_iter().map(|v| v as f32)
        })
        .collect()
}

/// What one incidence angle's samples need.
struct Samples<'a> {
    table: &'a MerlTable,
    ndf: &'a Marginal2D,
    sigma: &'a Marginal2D,
    vndf: &'a Marginal2D,
    side: usize,
}

/// One incidence angle's `rgb` (3 channel planes), `luminance` and validity.
struct Slice {
    rgb: Vec<f32>,
    luminance: Vec<f32>,
    valid: Vec<bool>,
}

impl Samples<'_> {
    fn slice(&self, theta_i: f32) -> Slice {
        let m = self.side;
        let params = [0.0f32, theta_i];
        // The last node is the horizon itself (pi/2 rounded to f32 lies just below it): the
        // slice holds the limit of the table towards it, read just above.
        let wi = direction(f64::from(theta_i).min(FRAC_PI_2 - GRAZING_MARGIN), 0.0);
        let u_wi = [(theta_i / std::f32::consts::FRAC_PI_2).sqrt(), 0.5];
        let four_sigma = 4.0 * f64::from(self.sigma.eval(u_wi, &[]));
        let mut out = Slice {
            rgb: vec![0.0; 3 * m * m],
            luminance: vec![0.0; m * m],
            valid: vec![false; m * m],
        };
        for i in 0..m * m {
            let (row, col) = (i / m, i % m);
            let pos = [col as f32 / (m - 1) as f32, row as f32 / (m - 1) as f32];
            let (u_m, _) = self.vndf.sample(pos, &params);
            let theta_m = f64::from(u_m[0]).powi(2) * FRAC_PI_2;
            let phi_m = (2.0 * f64::from(u_m[1]) - 1.0) * PI;
            let h = direction(theta_m, phi_m);
            let k = 2.0 * (h[0] * wi[0] + h[1] * wi[1] + h[2] * wi[2]);
            let wo = [k * h[0] - wi[0], k * h[1] - wi[1], k * h[2] - wi[2]];
            let d = f64::from(self.ndf.eval(u_m, &[]));
            if !(wo[2] > 0.0 && d > 0.0) {
                continue;
            }
            out.valid[i] = true;
            let scale = wo[2] * four_sigma / d;
            let f = brdf(self.table, wi, wo);
            for c in 0..3 {
                out.rgb[c * m * m + i] = (f[c] * scale) as f32;
            }
            out.luminance[i] = (luminance(f) * scale).max(0.0) as f32;
        }
        out.fill_horizon(m);
        if !out.luminance.iter().any(|&l| l > 0.0) {
            out.luminance.iter_mut().for_each(|l| *l = 1.0);
        }
        out
    }
}

impl Slice {
    /// Gives each node below the horizon that borders a node above it the mean of those
    /// neighbours, so a cell the horizon crosses is not darkened towards zero.
    fn fill_horizon(&mut self, m: usize) {
        let valid = &self.valid;
        for i in (0..m * m).filter(|&i| !valid[i]) {
            let (row, col) = (i / m, i % m);
            let sides = [
                (row > 0).then(|| i - m),
                (row + 1 < m).then(|| i + m),
                (col > 0).then(|| i - 1),
                (col + 1 < m).then(|| i + 1),
            ];
            let near: Vec<usize> = sides.into_iter().flatten().filter(|&j| valid[j]).collect();
            if near.is_empty() {
                continue;
            }
            let k = near.len() as f32;
            for c in 0..3 {
                self.rgb[c * m * m + i] =
                    near.iter().map(|&j| self.rgb[c * m * m + j]).sum::<f32>() / k;
            }
            self.luminance[i] = near.iter().map(|&j| self.luminance[j]).sum::<f32>() / k;
        }
    }
}
