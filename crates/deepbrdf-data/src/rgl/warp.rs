//! The 2-D marginal/conditional warp of the adaptive parameterization (Dupuy & Jakob 2018:
//! a bilinearly interpolated density on [0, 1]^2, sampled by inverting a marginal CDF over rows
//! and a conditional CDF over columns), optionally depending on extra parameters between whose
//! discretised values it interpolates linearly. A port of `Marginal2D` in the reference evaluator
//! `powitacq_rgb.inl`, in f32 as there, with the same bisection (`find_interval`), CDF
//! construction (trapezoids accumulated in f64), sampling, inversion and evaluation; the
//! parameter count is a run-time value instead of a template argument. The reference's fused
//! multiply-adds are plain multiply-then-add here (a difference of one rounding).

/// A 2-D piecewise-bilinear distribution on [0, 1]^2, x = columns (fastest), y = rows, with
/// `params.len()` conditioning parameters (the data are laid out `N0 x ... x Nn x rows x cols`).
#[derive(Debug, Clone)]
pub struct Marginal2D {
    /// Columns and rows of the discretisation (each >= 2).
    size: [usize; 2],
    patch_size: [f32; 2],
    inv_patch_size: [f32; 2],
    /// The discretised values of each parameter (sorted ascending).
    params: Vec<Vec<f32>>,
    /// Stride (in slices) of each parameter; 0 for a parameter with one value.
    strides: Vec<usize>,
    data: Vec<f32>,
    marginal_cdf: Vec<f32>,
    conditional_cdf: Vec<f32>,
}

/// Interpolation position along the parameters: the slice offset and, per parameter, the
/// weights of the lower and upper neighbouring value.
struct ParamWeights {
    slice_offset: usize,
    weights: Vec<[f32; 2]>,
}

/// `powitacq`'s `find_interval`: the index `i` in `[0, size - 2]` with `pred(i)` true and
/// `pred(i + 1)` false, by bisection (clamped when the predicate is true or false everywhere).
pub fn find_interval(size: usize, pred: impl Fn(usize) -> bool) -> usize {
    let mut len = size as isize - 2;
    let mut first: isize = 1;
    while len > 0 {
        let half = len >> 1;
        let middle = first + half;
        if pred(middle as usize) {
            first = middle + 1;
            len -= half + 1;
        } else {
            len = half;
        }
    }
    (first - 1).clamp(0, (size as isize - 2).max(0)) as usize
}

impl Marginal2D {
    /// Builds the distribution of `data` (`prod(params lens) x size[1] x size[0]` values).
    /// With `build_cdf`, each slice is normalised to integrate to 1 and the CDFs are built (the
    /// warp can sample and invert); without it the values are kept as given (only
    /// [`Marginal2D::eval`] is meaningful). Errors (as text, for the caller to attach the file
    /// and field): a size below 2, a data length that does not match, parameter values not
    /// strictly increasing, a slice that integrates to zero or to a non-finite value.
    pub fn new(
        size: [usize; 2],
        data: &[f32],
        params: Vec<Vec<f32>>,
        build_cdf: bool,
    ) -> Result<Self, String> {
        if size[0] < 2 || size[1] < 2 {
            return Err(format!("resolution {} x {} (both must be at least 2)", size[1], size[0]));
        }
        let mut slices = 1usize;
        let mut strides = vec![0; params.len()];
        for (d, values) in params.iter().enumerate().rev() {
            if values.is_empty() {
                return Err(format!("parameter {d} has no values"));
            }
            if values.windows(2).any(|w| w[0].partial_cmp(&w[1]) != Some(std::cmp::Ordering::Less))
            {
                return Err(format!("parameter {d} values are not strictly increasing"));
            }
            strides[d] = if values.len() > 1 { slices } else { 0 };
            slices *= values.len();
        }
        let n_values = size[0] * size[1];
        if data.len() != slices * n_values {
            return Err(format!(
                "{} values, expected {slices} slices of {} x {}",
                data.len(),
                size[1],
                size[0]
            ));
        }
        let inv_patch_size = [(size[0] - 1) as f32, (size[1] - 1) as f32];
        let patch_size = [1.0 / inv_patch_size[0], 1.0 / inv_patch_size[1]];
        let mut out = Self {
            size,
            patch_size,
            inv_patch_size,
            params,
            strides,
            data: vec![0.0; data.len()],
            marginal_cdf: Vec::new(),
            conditional_cdf: Vec::new(),
        };
        let (nx, ny) = (size[0], size[1]);
        if build_cdf {
            out.marginal_cdf = vec![0.0; slices * ny];
            out.conditional_cdf = vec![0.0; slices * n_values];
            for slice in 0..slices {
                let src = &data[slice * n_values..(slice + 1) * n_values];
                let cond = &mut out.conditional_cdf[slice * n_values..(slice + 1) * n_values];
                for y in 0..ny {
                    let mut sum = 0.0f64;
                    let i = y * nx;
                    cond[i] = 0.0;
                    for x in 0..nx - 1 {
                        sum += 0.5 * (f64::from(src[i + x]) + f64::from(src[i + x + 1]));
                        cond[i + x + 1] = sum as f32;
                    }
                }
                let marg = &mut out.marginal_cdf[slice * ny..(slice + 1) * ny];
                marg[0] = 0.0;
                let mut sum = 0.0f64;
                for y in 0..ny - 1 {
                    sum += 0.5
                        * (f64::from(cond[(y + 1) * nx - 1]) + f64::from(cond[(y + 2) * nx - 1]));
                    marg[y + 1] = sum as f32;
                }
                let normalization = 1.0 / marg[ny - 1];
                if !(normalization.is_finite() && normalization > 0.0) {
                    return Err(format!(
                        "slice {slice} integrates to {} (a density needs a positive integral)",
                        marg[ny - 1]
                    ));
                }
                cond.iter_mut().for_each(|v| *v *= normalization);
                marg.iter_mut().for_each(|v| *v *= normalization);
                for (o, &v) in
                    out.data[slice * n_values..(slice + 1) * n_values].iter_mut().zip(src)
                {
                    *o = v * normalization;
                }
            }
        } else {
            let normalization = 1.0 / (inv_patch_size[0] * inv_patch_size[1]);
            for (o, &v) in out.data.iter_mut().zip(data) {
                *o = v * normalization;
            }
        }
        Ok(out)
    }

    /// Resolution (columns, rows).
    pub fn size(&self) -> [usize; 2] {
        self.size
    }

    /// Slice offset and interpolation weights at parameter values `param` (one per parameter).
    fn param_weights(&self, param: &[f32]) -> ParamWeights {
        let mut slice_offset = 0;
        let weights = self
            .params
            .iter()
            .enumerate()
            .map(|(d, values)| {
                if values.len() == 1 {
                    return [1.0, 0.0];
                }
                let p = param[d];
                let index = find_interval(values.len(), |i| values[i] <= p);
                let (p0, p1) = (values[index], values[index + 1]);
                let w1 = ((p - p0) / (p1 - p0)).clamp(0.0, 1.0);
                slice_offset += self.strides[d] * index;
                [1.0 - w1, w1]
            })
            .collect();
        ParamWeights { slice_offset, weights }
    }

    /// `data[at + i0]` interpolated over the parameters (the reference's recursive `lookup`):
    /// `size` is the distance between consecutive slices in `data`.
    fn lookup(&self, data: &[f32], at: usize, i0: usize, size: usize, w: &ParamWeights) -> f32 {
        self.lookup_dim(data, at, i0, size, w, self.params.len())
    }

    fn lookup_dim(
        &self,
        data: &[f32],
        at: usize,
        i0: usize,
        size: usize,
        w: &ParamWeights,
        dim: usize,
    ) -> f32 {
        if dim == 0 {
            return data[at + i0];
        }
        let i1 = i0 + self.strides[dim - 1] * size;
        let [w0, w1] = w.weights[dim - 1];
        let v0 = self.lookup_dim(data, at, i0, size, w, dim - 1);
        let v1 = self.lookup_dim(data, at, i1, size, w, dim - 1);
        v0 * w0 + v1 * w1
    }

    /// Cell position (clamped to the last patch) and in-patch fraction of a point of [0, 1]^2.
    fn patch(&self, pos: [f32; 2]) -> ([usize; 2], [f32; 2]) {
        let s = [pos[0] * self.inv_patch_size[0], pos[1] * self.inv_patch_size[1]];
        // `as usize` saturates (NaN and negatives become 0), like the reference's conversion on
        // the inputs it is given.
        let cell = [(s[0] as usize).min(self.size[0] - 2), (s[1] as usize).min(self.size[1] - 2)];
        (cell, [s[0] - cell[0] as f32, s[1] - cell[1] as f32])
    }

    /// The density (or the raw interpolated value, for a warp built without CDFs) at `pos` in
    /// [0, 1]^2 and parameters `param`.
    pub fn eval(&self, pos: [f32; 2], param: &[f32]) -> f32 {
        let w = self.param_weights(param);
        let (cell, w1) = self.patch(pos);
        let w0 = [1.0 - w1[0], 1.0 - w1[1]];
        let size = self.size[0] * self.size[1];
        let index = cell[0] + cell[1] * self.size[0] + w.slice_offset * size;
        let nx = self.size[0];
        let v00 = self.lookup(&self.data, 0, index, size, &w);
        let v10 = self.lookup(&self.data, 1, index, size, &w);
        let v01 = self.lookup(&self.data, nx, index, size, &w);
        let v11 = self.lookup(&self.data, nx + 1, index, size, &w);
        (w0[1] * (w0[0] * v00 + w1[0] * v10) + w1[1] * (w0[0] * v01 + w1[0] * v11))
            * (self.inv_patch_size[0] * self.inv_patch_size[1])
    }

    /// Warps a uniform sample of [0, 1]^2 to the distribution: the point and its density.
    /// Only for warps built with CDFs.
    pub fn sample(&self, sample: [f32; 2], param: &[f32]) -> ([f32; 2], f32) {
        const ONE_MINUS_EPSILON: f32 = 0.999_999_94;
        let mut s = sample.map(|v| v.clamp(1.0 - ONE_MINUS_EPSILON, ONE_MINUS_EPSILON));
        let w = self.param_weights(param);
        let (nx, ny) = (self.size[0], self.size[1]);
        let slice_size = nx * ny;
        let marginal_at = w.slice_offset * ny;
        let fetch_marginal = |i: usize| self.lookup(&self.marginal_cdf, 0, marginal_at + i, ny, &w);
        let row = find_interval(ny, |i| fetch_marginal(i) < s[1]);
        s[1] -= fetch_marginal(row);
        let offset = row * nx + w.slice_offset * slice_size;
        let cdf = &self.conditional_cdf;
        let r0 = self.lookup(cdf, 0, offset + nx - 1, slice_size, &w);
        let r1 = self.lookup(cdf, 0, offset + 2 * nx - 1, slice_size, &w);
        let is_const = (r0 - r1).abs() < 1e-4 * (r0 + r1);
        s[1] = if is_const { 2.0 * s[1] } else { r0 - (r0 * r0 - 2.0 * s[1] * (r0 - r1)).sqrt() };
        s[1] /= if is_const { r0 + r1 } else { r0 - r1 };
        s[0] *= (1.0 - s[1]) * r0 + s[1] * r1;
        let sy = s[1];
        let fetch_conditional = |i: usize| {
            let v0 = self.lookup(cdf, 0, offset + i, slice_size, &w);
            let v1 = self.lookup(cdf, nx, offset + i, slice_size, &w);
            (1.0 - sy) * v0 + sy * v1
        };
        let col = find_interval(nx, |i| fetch_conditional(i) < s[0]);
        s[0] -= fetch_conditional(col);
        let offset = offset + col;
        let v00 = self.lookup(&self.data, 0, offset, slice_size, &w);
        let v10 = self.lookup(&self.data, 1, offset, slice_size, &w);
        let v01 = self.lookup(&self.data, nx, offset, slice_size, &w);
        let v11 = self.lookup(&self.data, nx + 1, offset, slice_size, &w);
        let c0 = (1.0 - s[1]) * v00 + s[1] * v01;
        let c1 = (1.0 - s[1]) * v10 + s[1] * v11;
        let is_const = (c0 - c1).abs() < 1e-4 * (c0 + c1);
        s[0] = if is_const { 2.0 * s[0] } else { c0 - (c0 * c0 - 2.0 * s[0] * (c0 - c1)).sqrt() };
        s[0] /= if is_const { c0 + c1 } else { c0 - c1 };
        (
            [(col as f32 + s[0]) * self.patch_size[0], (row as f32 + s[1]) * self.patch_size[1]],
            ((1.0 - s[0]) * c0 + s[0] * c1) * (self.inv_patch_size[0] * self.inv_patch_size[1]),
        )
    }

    /// The inverse of [`Marginal2D::sample`]: the uniform sample that warps to `pos`, and the
    /// density at `pos`. Only for warps built with CDFs.
    pub fn invert(&self, pos: [f32; 2], param: &[f32]) -> ([f32; 2], f32) {
        let w = self.param_weights(param);
        let (cell, mut s) = self.patch(pos);
        let (nx, ny) = (self.size[0], self.size[1]);
        let slice_size = nx * ny;
        let offset = cell[0] + cell[1] * nx + w.slice_offset * slice_size;
        let v00 = self.lookup(&self.data, 0, offset, slice_size, &w);
        let v10 = self.lookup(&self.data, 1, offset, slice_size, &w);
        let v01 = self.lookup(&self.data, nx, offset, slice_size, &w);
        let v11 = self.lookup(&self.data, nx + 1, offset, slice_size, &w);
        let (w1, w0) = (s, [1.0 - s[0], 1.0 - s[1]]);
        let c0 = w0[1] * v00 + w1[1] * v01;
        let c1 = w0[1] * v10 + w1[1] * v11;
        let pdf = w0[0] * c0 + w1[0] * c1;
        s[0] *= c0 + 0.5 * s[0] * (c1 - c0);
        let cdf = &self.conditional_cdf;
        let v0 = self.lookup(cdf, 0, offset, slice_size, &w);
        let v1 = self.lookup(cdf, nx, offset, slice_size, &w);
        s[0] += (1.0 - s[1]) * v0 + s[1] * v1;
        let offset = cell[1] * nx + w.slice_offset * slice_size;
        let r0 = self.lookup(cdf, 0, offset + nx - 1, slice_size, &w);
        let r1 = self.lookup(cdf, 0, offset + 2 * nx - 1, slice_size, &w);
        s[0] /= (1.0 - s[1]) * r0 + s[1] * r1;
        s[1] *= r0 + 0.5 * s[1] * (r1 - r0);
        let marginal_at = cell[1] + w.slice_offset * ny;
        s[1] += self.lookup(&self.marginal_cdf, 0, marginal_at, ny, &w);
        (s, pdf * (self.inv_patch_size[0] * self.inv_patch_size[1]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A lumpy positive density on a 9 x 7 grid, two slices along one parameter.
    fn lumpy() -> Marginal2D {
        let data: Vec<f32> = (0..2 * 7 * 9)
            .map(|i| {
                let (s, y, x) = (i / 63, (i / 9) % 7, i % 9);
                0.1 + ((x as f32 * 0.9 + s as f32).sin() * (y as f32 * 0.7).cos()).powi(2)
            })
            .collect();
        Marginal2D::new([9, 7], &data, vec![vec![0.0, 1.0]], true).expect("valid")
    }

    #[test]
    fn find_interval_brackets() {
        let v = [0.0f32, 1.0, 2.0, 3.0];
        assert_eq!(find_interval(4, |i| v[i] <= 1.5), 1);
        assert_eq!(find_interval(4, |i| v[i] <= -1.0), 0);
        assert_eq!(find_interval(4, |i| v[i] <= 9.0), 2);
        assert_eq!(find_interval(4, |i| v[i] <= 3.0), 2);
        assert_eq!(find_interval(2, |_| true), 0);
    }

    #[test]
    fn sample_and_invert_round_trip_and_densities_agree() {
        let warp = lumpy();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..2000 {
            let u = [rng.random_range(0.0..1.0f32), rng.random_range(0.0..1.0f32)];
            let p = [rng.random_range(0.0..1.0f32)];
            let (x, pdf) = warp.sample(u, &p);
            let (back, pdf_back) = warp.invert(x, &p);
            assert!(
                (back[0] - u[0]).abs() < 2e-4 && (back[1] - u[1]).abs() < 2e-4,
                "{u:?} {back:?}"
            );
            assert!((pdf - pdf_back).abs() < 1e-3 * pdf, "{pdf} {pdf_back}");
            assert!((warp.eval(x, &p) - pdf).abs() < 1e-3 * pdf);
        }
    }

    #[test]
    fn density_integrates_to_one() {
        let warp = lumpy();
        let n = 400;
        for p in [0.0f32, 0.3, 1.0] {
            let mut sum = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let pos = [(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32];
                    sum += f64::from(warp.eval(pos, &[p]));
                }
            }
            let integral = sum / (n * n) as f64;
            assert!((integral - 1.0).abs() < 1e-3, "{p}: {integral}");
        }
    }

    #[test]
    fn bad_shapes_are_refused() {
        assert!(Marginal2D::new([1, 5], &[1.0; 5], vec![], true).is_err());
        assert!(Marginal2D::new([2, 2], &[1.0; 3], vec![], true).is_err());
        assert!(Marginal2D::new([2, 2], &[0.0; 4], vec![], true)
            .expect_err("zero")
            .contains("integrates"));
        assert!(Marginal2D::new([2, 2], &[1.0; 8], vec![vec![1.0, 1.0]], true).is_err());
        assert!(Marginal2D::new([2, 2], &[0.0; 4], vec![], false).is_ok());
    }
}
