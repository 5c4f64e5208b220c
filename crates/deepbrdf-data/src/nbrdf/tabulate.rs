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
use crate::merl::{grid, MerlTable, CELLS, INVALID_VALUE, N_PHI_D, N_THETA_D, N_THETA_H, VALUES};
use rayon::prelude::*;

/// Version of the tabulation procedure. Bump it whenever the values this module produces change
/// (sample angles, clamping, arithmetic), so cached tables are recomputed.
pub const TABULATOR_VERSION: u32 = 1;

/// Cells evaluated together in one structure-of-arrays block.
const BLOCK: usize = 64;
/// Cells in one theta_h row of the grid (all theta_d and phi_d).
const ROW: usize = N_THETA_D * N_PHI_D;

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
    x: [[f32; BLOCK]; INPUTS],
    /// Row-local cell index (theta_d * 180 + phi_d) of each lane.
    cell: [usize; BLOCK],
    len: usize,
}

/// Forward pass of a block: `out[c][lane]` = RGB of each lane (only `len` lanes are meaningful).
fn forward_block(net: &Network, x: &[[f32; BLOCK]; INPUTS], out: &mut [[f32; BLOCK]; OUTPUTS]) {
    let mut h1 = [[0f32; BLOCK]; HIDDEN];
    for (o, acc) in h1.iter_mut().enumerate() {
        *acc = [net.b1[o]; BLOCK];
        for (w, xk) in net.w1[o].iter().zip(x) {
            for (a, v) in acc.iter_mut().zip(xk) {
                *a += w * v;
            }
        }
        acc.iter_mut().for_each(|a| *a = a.max(0.0));
    }
    let mut h2 = [[0f32; BLOCK]; HIDDEN];
    for (o, acc) in h2.iter_mut().enumerate() {
        *acc = [net.b2[o]; BLOCK];
        for (w, hk) in net.w2[o].iter().zip(&h1) {
            for (a, v) in acc.iter_mut().zip(hk) {
                *a += w * v;
            }
        }
        acc.iter_mut().for_each(|a| *a = a.max(0.0));
    }
    for (o, acc) in out.iter_mut().enumerate() {
        *acc = [net.b3[o]; BLOCK];
        for (w, hk) in net.w3[o].iter().zip(&h2) {
            for (a, v) in acc.iter_mut().zip(hk) {
                *a += w * v;
            }
        }
        acc.iter_mut().for_each(|a| *a = a.exp_m1());
    }
}

/// The validity of every cell ([`grid::cell_is_valid`]), computed once per process.
fn valid_cells() -> &'static [bool] {
    static MASK: std::sync::OnceLock<Vec<bool>> = std::sync::OnceLock::new();
    MASK.get_or_init(|| {
        (0..CELLS)
            .map(|cell| {
                let (i, j, k) = crate::merl::cell_coords(cell);
                grid::cell_is_valid(i, j, k)
            })
            .collect()
    })
}

/// Fills one theta_h row (`i`) of the three channels.
fn tabulate_row(net: &Network, trig: &GridTrig, i: usize, rows: [&mut [f32]; 3]) {
    let [r, g, b] = rows;
    let mut out = [[0f32; BLOCK]; OUTPUTS];
    let mut block = Block { x: [[0f32; BLOCK]; INPUTS], cell: [0; BLOCK], len: 0 };
    let (sh, ch) = (trig.sin_h[i] as f32, trig.cos_h[i] as f32);
    let mut flush = |block: &mut Block, r: &mut [f32], g: &mut [f32], b: &mut [f32]| {
        forward_block(net, &block.x, &mut out);
        for lane in 0..block.len {
            let c = block.cell[lane];
            r[c] = out[0][lane].max(0.0);
            g[c] = out[1][lane].max(0.0);
            b[c] = out[2][lane].max(0.0);
        }
        block.len = 0;
    };
    let valid = &valid_cells()[i * ROW..(i + 1) * ROW];
    for j in 0..N_THETA_D {
        let (sd, cd) = (trig.sin_d[j], trig.cos_d[j]);
        for k in 0..N_PHI_D {
            if !valid[j * N_PHI_D + k] {
                continue;
            }
            let lane = block.len;
            block.x[0][lane] = sh;
            block.x[1][lane] = 0.0;
            block.x[2][lane] = ch;
            block.x[3][lane] = (sd * trig.cos_p[k]) as f32;
            block.x[4][lane] = (sd * trig.sin_p[k]) as f32;
            block.x[5][lane] = cd as f32;
            block.cell[lane] = j * N_PHI_D + k;
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
    let mut values = vec![INVALID_VALUE; VALUES];
    let (r, rest) = values.split_at_mut(CELLS);
    let (g, b) = rest.split_at_mut(CELLS);
    r.par_chunks_mut(ROW)
        .zip(g.par_chunks_mut(ROW))
        .zip(b.par_chunks_mut(ROW))
        .enumerate()
        .for_each(|(i, ((r, g), b))| tabulate_row(net, &trig, i, [r, g, b]));
    MerlTable::from_values(values).map_err(|e| {
        DataError::Invalid(format!("network {} tabulates to an invalid table: {e}", net.name()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::merl::{cell_coords, cell_index};
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
