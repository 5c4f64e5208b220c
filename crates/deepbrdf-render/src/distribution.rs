//! Piecewise-constant 1D and 2D distributions for importance sampling (Pharr, Jakob and
//! Humphreys, "Physically Based Rendering", 3rd ed., §13.3.1 and §13.6.7).

/// A piecewise-constant density on [0, 1) with `n` equal bins, proportional to `func`.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    func: Vec<f64>,
    /// `cdf[i]` = probability of bins `< i`; `cdf[n] = 1`.
    cdf: Vec<f64>,
    /// Integral of `func` over [0, 1).
    integral: f64,
    /// Guide table (Chen's cutpoint method): `guide[k]` is the last bin whose CDF start is
    /// `<= k / n`, where the search for `u` in `[k/n, (k+1)/n)` starts; O(1) expected steps.
    guide: Vec<u32>,
}

impl Distribution1D {
    /// The distribution proportional to `func` (non-negative; all-zero gives a uniform one).
    pub fn new(func: Vec<f64>) -> Self {
        let n = func.len().max(1);
        let func = if func.is_empty() { vec![1.0] } else { func };
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        for (i, f) in func.iter().enumerate() {
            cdf.push(cdf[i] + f.max(0.0) / n as f64);
        }
        let integral = cdf[n];
        if integral > 0.0 {
            cdf.iter_mut().for_each(|c| *c /= integral);
        } else {
            cdf.iter_mut().enumerate().for_each(|(i, c)| *c = i as f64 / n as f64);
        }
        cdf[n] = 1.0;
        let mut guide = Vec::with_capacity(n);
        let mut i = 0;
        for k in 0..n {
            let u = k as f64 / n as f64;
            while i + 1 < n && cdf[i + 1] <= u {
                i += 1;
            }
            guide.push(i as u32);
        }
        Self { func, cdf, integral, guide }
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// Whether there are no bins (never: an empty function gets one bin).
    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// Integral of the function over [0, 1).
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// Density (w.r.t. [0, 1)) of bin `i`.
    #[inline]
    pub fn pdf_bin(&self, i: usize) -> f64 {
        if self.integral > 0.0 {
            self.func[i].max(0.0) / self.integral
        } else {
            1.0
        }
    }

    /// Inverts the CDF at `u` in [0, 1): `(x in [0, 1), bin index, density at x)`.
    #[inline]
    pub fn sample(&self, u: f64) -> (f64, usize, f64) {
        let n = self.func.len();
        // Last bin with cdf <= u, searched upwards from the guide table's entry.
        let k = ((u * n as f64) as usize).min(n - 1);
        let mut i = self.guide[k] as usize;
        while i + 1 < n && self.cdf[i + 1] <= u {
            i += 1;
        }
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 { ((u - self.cdf[i]) / width).clamp(0.0, 1.0) } else { 0.5 };
        let x = ((i as f64 + du) / n as f64).min(1.0 - f64::EPSILON);
        (x, i, self.pdf_bin(i))
    }
}

/// A piecewise-constant density on [0, 1)^2 over a `width x height` grid, proportional to
/// `func` (row-major, `func[row * width + col]`): a marginal over rows and a conditional over
/// columns within each row.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    width: usize,
    conditional: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// The distribution proportional to `func`. `width * height` must equal `func.len()`.
    pub fn new(func: &[f64], width: usize, height: usize) -> Self {
        assert_eq!(func.len(), width * height, "Distribution2D: func has the wrong length");
        let conditional: Vec<Distribution1D> =
            func.chunks(width).map(|row| Distribution1D::new(row.to_vec())).collect();
        let marginal = Distribution1D::new(conditional.iter().map(|c| c.integral()).collect());
        Self { width, conditional, marginal }
    }

    /// `((u, v) in [0,1)^2, (col, row), density w.r.t. du dv)` for uniform `u`.
    #[inline]
    pub fn sample(&self, u: [f64; 2]) -> ([f64; 2], (usize, usize), f64) {
        let (v, row, p_row) = self.marginal.sample(u[1]);
        let (x, col, p_col) = self.conditional[row].sample(u[0]);
        ([x, v], (col, row), p_row * p_col)
    }

    /// Density w.r.t. du dv of the cell (`col`, `row`).
    #[inline]
    pub fn pdf_cell(&self, col: usize, row: usize) -> f64 {
        self.marginal.pdf_bin(row) * self.conditional[row].pdf_bin(col)
    }

    /// Grid width (columns).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Grid height (rows).
    pub fn height(&self) -> usize {
        self.conditional.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn one_dimensional_sampling_follows_the_function() {
        let d = Distribution1D::new(vec![1.0, 0.0, 3.0, 4.0]);
        assert!((d.integral() - 2.0).abs() < 1e-12);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut counts = [0usize; 4];
        let n = 80_000;
        for _ in 0..n {
            let (x, i, p) = d.sample(rng.random());
            assert!((0.0..1.0).contains(&x));
            assert_eq!(i, (x * 4.0) as usize);
            assert!((p - d.pdf_bin(i)).abs() < 1e-12);
            counts[i] += 1;
        }
        assert_eq!(counts[1], 0);
        for (i, want) in [(0, 1.0 / 8.0), (2, 3.0 / 8.0), (3, 4.0 / 8.0)] {
            let got = counts[i] as f64 / n as f64;
            assert!((got - want).abs() < 0.01, "bin {i}: {got} vs {want}");
        }
        // Density integrates to one: pdf_bin / n summed over bins.
        let total: f64 = (0..4).map(|i| d.pdf_bin(i) / 4.0).sum();
        assert!((total - 1.0).abs() < 1e-12);
    }

    #[test]
    fn guide_table_agrees_with_binary_search() {
        let d = Distribution1D::new(vec![0.0, 5.0, 0.0, 0.0, 1.0, 0.1, 0.0, 7.0, 0.0]);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..20_000 {
            let u: f64 = rng.random();
            let (_, i, _) = d.sample(u);
            let j = (d.cdf.partition_point(|&c| c <= u) - 1).min(d.len() - 1);
            assert_eq!(i, j, "u {u}");
        }
    }

    #[test]
    fn two_dimensional_pdf_is_consistent() {
        let func: Vec<f64> = (0..12).map(|i| (i % 5) as f64 + 0.5).collect();
        let d = Distribution2D::new(&func, 4, 3);
        let total: f64 = (0..3)
            .flat_map(|r| (0..4).map(move |c| (c, r)))
            .map(|(c, r)| d.pdf_cell(c, r) / 12.0)
            .sum();
        assert!((total - 1.0).abs() < 1e-12);
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        for _ in 0..1000 {
            let (uv, (c, r), p) = d.sample([rng.random(), rng.random()]);
            assert_eq!(c, (uv[0] * 4.0) as usize);
            assert_eq!(r, (uv[1] * 3.0) as usize);
            assert!((p - d.pdf_cell(c, r)).abs() < 1e-12);
            // Density proportional to the function: p = func / mean(func).
            let mean = func.iter().sum::<f64>() / 12.0;
            assert!((p - func[r * 4 + c] / mean).abs() < 1e-9);
        }
    }
}
