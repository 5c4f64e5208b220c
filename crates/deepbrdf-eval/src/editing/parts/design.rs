//! The linear least-squares problem of the parts' colours ([`super::fit`]): the sampled cells
//! and their weights, each part shape's column, the normal equations of a set of columns (the
//! grid's computed once, the refinement's per shape), and their per-channel non-negative
//! solution (Lawson and Hanson 1974, ch. 23).

use super::{floor_shape, lobe_shape, retro_shape, sheen_shape, CellAngles, Distribution};
use deepbrdf_data::merl::{cell_index, CELLS, N_PHI_D, N_THETA_D, N_THETA_H};
use deepbrdf_data::MerlTable;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// One shape: a column of the design.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Shape {
    /// A floor of sigma and coat index.
    Floor(f64, Option<f64>),
    /// A lobe's normal-incidence (`false`) or grazing (`true`) column at roughness alpha.
    Lobe(Distribution, f64, bool),
    Retro(f64),
    Sheen(f64),
}

impl Shape {
    fn eval(self, a: &CellAngles) -> f64 {
        match self {
            Shape::Floor(sigma, coat) => floor_shape(sigma, coat, a),
            Shape::Lobe(distribution, alpha, grazing) => {
                let m = a.grazing();
                lobe_shape(distribution, alpha, a) * if grazing { m } else { 1.0 - m }
            }
            Shape::Retro(n) => retro_shape(n, a),
            Shape::Sheen(r) => sheen_shape(r, a),
        }
    }
}

/// The sampled cells: their angles, weights and values.
pub(super) struct Samples {
    pub(super) angles: Vec<CellAngles>,
    weight: Vec<f64>,
    values: [Vec<f64>; 3],
    /// `sum w v^2` per channel.
    pub(super) energy: [f64; 3],
}

impl Samples {
    /// The valid cells of `table` above the horizon at every theta_h, every `theta_d_stride`-th
    /// theta_d and `phi_d_stride`-th phi_d, weighted with the log space's offset `offset`.
    pub(super) fn of(
        table: &MerlTable,
        theta_d_stride: usize,
        phi_d_stride: usize,
        offset: f64,
    ) -> Self {
        let mut s = Samples {
            angles: vec![],
            weight: vec![],
            values: Default::default(),
            energy: [0.0; 3],
        };
        for i in 0..N_THETA_H {
            for j in (0..N_THETA_D).step_by(theta_d_stride) {
                for k in (0..N_PHI_D).step_by(phi_d_stride) {
                    let cell = cell_index(i, j, k);
                    let Some(a) = CellAngles::of(i, j, k) else { continue };
                    if !table.is_valid(cell) {
                        continue;
                    }
                    let v: [f64; 3] =
                        std::array::from_fn(|c| f64::from(table.values()[c * CELLS + cell]));
                    let w = a.cos_i * a.cos_o;
                    let mean = (v[0] + v[1] + v[2]) / 3.0;
                    let weight = (w / (offset + w * mean)).powi(2);
                    s.angles.push(a);
                    s.weight.push(weight);
                    for c in 0..3 {
                        s.values[c].push(v[c]);
                        s.energy[c] += weight * v[c] * v[c];
                    }
                }
            }
        }
        s
    }

    fn column(&self, shape: Shape) -> Vec<f64> {
        self.angles.par_iter().map(|a| shape.eval(a)).collect()
    }

    /// `sum w x y`.
    fn dot(&self, x: &[f64], y: &[f64]) -> f64 {
        self.weight.iter().zip(x.iter().zip(y)).map(|(w, (a, b))| w * a * b).sum()
    }
}

/// The normal equations of a set of columns: the Gram matrix and each channel's right side.
pub(super) struct Normal {
    gram: DMatrix<f64>,
    rhs: [DVector<f64>; 3],
}

impl Normal {
    /// The normal equations of `columns` over `samples`.
    fn of(samples: &Samples, columns: &[&[f64]]) -> Self {
        let m = columns.len();
        let pairs: Vec<(usize, usize)> = (0..m).flat_map(|i| (i..m).map(move |j| (i, j))).collect();
        let dots: Vec<f64> =
            pairs.par_iter().map(|&(i, j)| samples.dot(columns[i], columns[j])).collect();
        let mut gram = DMatrix::zeros(m, m);
        for (&(i, j), &d) in pairs.iter().zip(&dots) {
            gram[(i, j)] = d;
            gram[(j, i)] = d;
        }
        let rhs = std::array::from_fn(|c| {
            let dots: Vec<f64> =
                columns.par_iter().map(|col| samples.dot(col, &samples.values[c])).collect();
            DVector::from_vec(dots)
        });
        Self { gram, rhs }
    }
}

/// The columns of every grid shape and their normal equations, computed once.
pub(super) struct Design {
    shapes: Vec<Shape>,
    normal: Normal,
}

impl Design {
    pub(super) fn new(samples: &Samples, shapes: Vec<Shape>) -> Self {
        let columns: Vec<Vec<f64>> = shapes.par_iter().map(|&s| samples.column(s)).collect();
        let refs: Vec<&[f64]> = columns.iter().map(Vec::as_slice).collect();
        Self { normal: Normal::of(samples, &refs), shapes }
    }

    fn index(&self, shape: Shape) -> usize {
        self.shapes.iter().position(|&s| s == shape).expect("a grid shape")
    }

    /// The normal equations of `shapes`, all of them on the grid.
    pub(super) fn normal(&self, shapes: &[Shape]) -> Normal {
        let idx: Vec<usize> = shapes.iter().map(|&s| self.index(s)).collect();
        let m = idx.len();
        let (gram, rhs) = (&self.normal.gram, &self.normal.rhs);
        Normal {
            gram: DMatrix::from_fn(m, m, |a, b| gram[(idx[a], idx[b])]),
            rhs: std::array::from_fn(|c| DVector::from_fn(m, |a, _| rhs[c][idx[a]])),
        }
    }
}

/// Columns computed off the grid during the refinement, each shape once.
pub(super) struct Columns<'a> {
    samples: &'a Samples,
    computed: Vec<(Shape, Vec<f64>)>,
}

impl<'a> Columns<'a> {
    pub(super) fn new(samples: &'a Samples) -> Self {
        Self { samples, computed: Vec::new() }
    }

    /// The normal equations of `shapes`.
    pub(super) fn normal(&mut self, shapes: &[Shape]) -> Normal {
        for &shape in shapes {
            if !self.computed.iter().any(|(s, _)| *s == shape) {
                self.computed.push((shape, self.samples.column(shape)));
            }
        }
        let columns: Vec<&[f64]> = shapes
            .iter()
            .map(|shape| {
                self.computed.iter().find(|(s, _)| s == shape).expect("computed").1.as_slice()
            })
            .collect();
        Normal::of(self.samples, &columns)
    }
}

/// Each channel's non-negative colours and the relative error of the solution.
pub(super) fn solve(normal: &Normal, energy: &[f64; 3]) -> ([DVector<f64>; 3], f64) {
    let x: [DVector<f64>; 3] = std::array::from_fn(|c| nnls(&normal.gram, &normal.rhs[c]));
    let residual: f64 = (0..3)
        .map(|c| {
            let x = &x[c];
            energy[c] - 2.0 * x.dot(&normal.rhs[c]) + x.dot(&(&normal.gram * x))
        })
        .sum();
    let total: f64 = energy.iter().sum();
    (x, (residual / total.max(f64::MIN_POSITIVE)).max(0.0))
}

/// Lawson and Hanson's active-set solution of `min x' G x - 2 r' x` over `x >= 0`, `G` the
/// (positive semi-definite) Gram matrix of the columns.
fn nnls(gram: &DMatrix<f64>, rhs: &DVector<f64>) -> DVector<f64> {
    let m = rhs.len();
    let scale = (0..m).map(|i| gram[(i, i)]).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    let tol = 1e-12 * scale;
    let mut x = DVector::zeros(m);
    let mut passive = vec![false; m];
    for _ in 0..3 * m {
        let w = rhs - gram * &x;
        let next =
            (0..m).filter(|&j| !passive[j] && w[j] > tol).max_by(|&a, &b| w[a].total_cmp(&w[b]));
        let Some(j) = next else { break };
        passive[j] = true;
        for _ in 0..3 * m {
            let p: Vec<usize> = (0..m).filter(|&i| passive[i]).collect();
            let z = solve_passive(gram, rhs, &p);
            if p.iter().zip(z.iter()).all(|(_, &v)| v > 0.0) {
                p.iter().zip(z.iter()).for_each(|(&i, &v)| x[i] = v);
                break;
            }
            // Step from x towards z until the first passive value reaches 0; drop it.
            let step = p
                .iter()
                .zip(z.iter())
                .filter(|(_, &v)| v <= 0.0)
                .map(|(&i, &v)| x[i] / (x[i] - v))
                .fold(1.0, f64::min);
            for (&i, &v) in p.iter().zip(z.iter()) {
                x[i] += step * (v - x[i]);
                if x[i] <= 1e-15 * scale.sqrt() {
                    x[i] = 0.0;
                    passive[i] = false;
                }
            }
            if !passive.iter().any(|&b| b) {
                break;
            }
        }
    }
    x
}

/// The unconstrained solution over the passive columns `p` (a small ridge keeps a nearly
/// dependent pair solvable).
fn solve_passive(gram: &DMatrix<f64>, rhs: &DVector<f64>, p: &[usize]) -> Vec<f64> {
    let n = p.len();
    let ridge = 1e-10 * p.iter().map(|&i| gram[(i, i)]).sum::<f64>() / n as f64;
    let g = DMatrix::from_fn(n, n, |a, b| gram[(p[a], p[b])] + if a == b { ridge } else { 0.0 });
    let r = DVector::from_fn(n, |a, _| rhs[p[a]]);
    match g.clone().cholesky() {
        Some(ch) => ch.solve(&r).iter().copied().collect(),
        None => g.lu().solve(&r).map_or(vec![0.0; n], |v| v.iter().copied().collect()),
    }
}
