//! Tabulating a [`Network`] onto the MERL grid, fast: f32 arithmetic on blocks of cells laid out
//! structure-of-arrays (so every inner loop runs over a block and vectorises), one theta_h row of
//! the grid per rayon task.
//!
//! Each valid cell (both directions above the horizon, [`grid::cell_is_valid`]) is evaluated at
//! its sample angles ([`grid::theta_h_of`], [`grid::theta_d_of`], [`grid::phi_d_of`]); invalid
//! cells get [`INVALID_VALUE`]. Network outputs below zero (a fit's small undershoot, since
//! `exp(x) - 1 > -1`) are clamped to 0, because a negative value marks a cell invalid in MERL's
//! convention.

use super::network::{Network, HIDDEN, INPUTS, OUTPUTS};
use crate::error::{DataError, Result};
use crate::merl::grid::ROW;
use crate::merl::{grid, MerlTable, N_PHI_D, N_THETA_D, N_THETA_H};

/// Version of the tabulation procedure. Bump it whenever the values this module produces change
/// (sample angles, clamping, arithmetic), so cached tables are recomputed.
/// Version 2: cells sampled at their bin centres ([`grid`]), no longer at the lower edges.
pub const TABULATOR_VERSION: u32 = 2;

/// Cells evaluated together in one structure-of-arrays block.
const BLOCK: usize = 64;
/// Width of the vectors the inner loops work on (one AVX register of f32).
const LANES: usize = 8;
/// Vectors per block.
const CHUNKS: usize = BLOCK / LANES;
/// `N` values for each cell of a block: `v[n][chunk][lane]` is value `n` of cell
/// `chunk * LANES + lane`.
type Lanes<const N: usize> = [[[f32; LANES]; CHUNKS]; N];

/// Sines and cosines of the grid's sample angles, in f64 then rounded once to f32.
struct GridTrig {
    sin_h: Vec<f64>,
    cos_h: Vec<f64>,
    sin_d: Vec<f64>,
    cos_d: Vec<f64>,
    sin_p: Vec<f64>,
    cos_p: Vec<f64>,
}

impl GridTrig {
    fn new() -> Self {
        let (sin_h, cos_h) = (0..N_THETA_H).map(|i| grid::theta_h_of(i).sin_cos()).unzip();
        let (sin_d, cos_d) = (0..N_THETA_D).map(|j| grid::theta_d_of(j).sin_cos()).unzip();
        let (sin_p, cos_p) = (0..N_PHI_D).map(|k| grid::phi_d_of(k).sin_cos()).unzip();
        Self { sin_h, cos_h, sin_d, cos_d, sin_p, cos_p }
    }
}

/// Inputs of one block, one array per input component.
struct Block {
    x: Lanes<INPUTS>,
    /// Row-local cell index (theta_d * 180 + phi_d) of each cell.
    cell: [usize; BLOCK],
    len: usize,
}

/// One dense layer on a block, `y = act(W x + b)`: each output accumulates, per vector of
/// [`LANES`] cells, the bias and then the inputs in order (so the accumulator stays in a
/// register).
#[inline(always)]
fn dense<const IN: usize, const OUT: usize>(
    w: &[[f32; IN]; OUT],
    b: &[f32; OUT],
    x: &Lanes<IN>,
    y: &mut Lanes<OUT>,
    act: impl Fn(f32) -> f32,
) {
    for o in 0..OUT {
        for c in 0..CHUNKS {
            let mut acc = [b[o]; LANES];
            for k in 0..IN {
                let w = w[o][k];
                for l in 0..LANES {
                    acc[l] += w * x[k][c][l];
                }
            }
            for l in 0..LANES {
                y[o][c][l] = act(acc[l]);
            }
        }
    }
}

/// Forward pass of a block up to the output layer's pre-activation: `out[c]` = `W3 h2 + b3` for
/// channel `c` of each cell (only `len` cells are meaningful; the caller applies
/// `exp(x) - 1` to those). Inlined into a [`pulp::Arch::dispatch`] operation, so its loops are
/// vectorised for the best instruction set the CPU has (AVX2 where available). Plain multiply
/// then add, never a fused multiply-add, so every instruction set gives bit-identical tables.
#[inline(always)]
fn forward_block(net: &Network, x: &Lanes<INPUTS>, out: &mut Lanes<OUTPUTS>) {
    let relu = |a: f32| a.max(0.0);
    let mut h1 = [[[0f32; LANES]; CHUNKS]; HIDDEN];
    dense(&net.w1, &net.b1, x, &mut h1, relu);
    let mut h2 = [[[0f32; LANES]; CHUNKS]; HIDDEN];
    dense(&net.w2, &net.b2, &h1, &mut h2, relu);
    dense(&net.w3, &net.b3, &h2, out, |a| a);
}

/// [`forward_block`] as a [`pulp::WithSimd`] operation: `Arch::dispatch` runs it inside a
/// function compiled for the detected instruction set, with the forward pass inlined into it.
struct ForwardOp<'a> {
    net: &'a Network,
    x: &'a Lanes<INPUTS>,
    out: &'a mut Lanes<OUTPUTS>,
}

impl pulp::WithSimd for ForwardOp<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        forward_block(self.net, self.x, self.out);
    }
}

/// Fills one theta_h row (`i`) of the three channels.
fn tabulate_row(net: &Network, trig: &GridTrig, i: usize, rows: [&mut [f32]; 3]) {
    let [r, g, b] = rows;
    let mut out = [[[0f32; LANES]; CHUNKS]; OUTPUTS];
    let mut block = Block { x: [[[0f32; LANES]; CHUNKS]; INPUTS], cell: [0; BLOCK], len: 0 };
    let (sh, ch) = (trig.sin_h[i] as f32, trig.cos_h[i] as f32);
    let arch = pulp::Arch::new();
    let mut flush = |block: &mut Block, r: &mut [f32], g: &mut [f32], b: &mut [f32]| {
        arch.dispatch(ForwardOp { net, x: &block.x, out: &mut out });
        for (n, &c) in block.cell[..block.len].iter().enumerate() {
            let (chunk, lane) = (n / LANES, n % LANES);
            r[c] = out[0][chunk][lane].exp_m1().max(0.0);
            g[c] = out[1][chunk][lane].exp_m1().max(0.0);
            b[c] = out[2][chunk][lane].exp_m1().max(0.0);
        }
        block.len = 0;
    };
    let valid = &grid::valid_mask()[i * ROW..(i + 1) * ROW];
    for j in 0..N_THETA_D {
        let (sd, cd) = (trig.sin_d[j], trig.cos_d[j]);
        for k in 0..N_PHI_D {
            if !valid[j * N_PHI_D + k] {
                continue;
            }
            let (chunk, lane) = (block.len / LANES, block.len % LANES);
            let input =
                [sh, 0.0, ch, (sd * trig.cos_p[k]) as f32, (sd * trig.sin_p[k]) as f32, cd as f32];
            for (xk, v) in block.x.iter_mut().zip(input) {
                xk[chunk][lane] = v;
            }
            block.cell[block.len] = j * N_PHI_D + k;
            block.len += 1;
            if block.len == BLOCK {
                flush(&mut block, r, g, b);
            }
        }
    }
    if block.len > 0 {
        flush(&mut block, r, g, b);
    }
}

/// Tabulates `net` onto the MERL grid: reflectance in 1/sr, invalid cells [`INVALID_VALUE`].
/// Runs in parallel over theta_h rows. Fails if the network produces non-finite values.
pub fn tabulate(net: &Network) -> Result<MerlTable> {
    let trig = GridTrig::new();
    MerlTable::from_par_rows(|i, rows| tabulate_row(net, &trig, i, rows)).map_err(|e| {
        DataError::Invalid(format!("network {} tabulates to an invalid table: {e}", net.name()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::merl::{cell_coords, cell_index, CELLS, INVALID_VALUE};
    use crate::nbrdf::network::PARAMETERS;
    use rand::{Rng, SeedableRng};

    /// A random network with weights of the magnitude the real ones have.
    fn random_network(seed: u64) -> Network {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let params: Vec<f32> = (0..PARAMETERS).map(|_| rng.random_range(-0.6..0.6)).collect();
        Network::from_parameters("random", &params).expect("valid")
    }

    #[test]
    fn tabulation_matches_the_f64_evaluator_and_the_horizon() {
        let net = random_network(7);
        let table = tabulate(&net).expect("finite");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let mut valid = 0;
        for _ in 0..20_000 {
            let cell = rng.random_range(0..CELLS);
            let (i, j, k) = cell_coords(cell);
            let rgb = table.rgb(i, j, k);
            if !grid::cell_is_valid(i, j, k) {
                assert_eq!(rgb, [INVALID_VALUE; 3], "cell {i},{j},{k}");
                continue;
            }
            valid += 1;
            let expect = net.evaluate(grid::theta_h_of(i), grid::theta_d_of(j), grid::phi_d_of(k));
            for c in 0..3 {
                let e = expect[c].max(0.0);
                let got = rgb[c] as f64;
                assert!(
                    (got - e).abs() <= 1e-5 * e.abs() + 1e-6,
                    "cell {i},{j},{k} c{c}: {got} vs {e}"
                );
            }
        }
        assert!(valid > 10_000);
        // Every cell at theta_h = 0 is valid; at the grazing corner none is.
        assert!(table.is_valid(cell_index(0, 89, 90)));
        assert!(!table.is_valid(cell_index(89, 89, 0)));
    }
}
