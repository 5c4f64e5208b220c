//! Small synthetic MERL tables for tests: a diffuse colour plus a specular lobe in theta_h,
//! a few parameters per material, so a handful of tables span a low-dimensional family.
//! Tables are built once per test process (in parallel) and shared.
//!
//! [`sparse_set`] gives the same materials measured only near the specular peak (theta_h index
//! below [`SPARSE_THETA_H`], the other cells invalid as if unmeasured): a basis fitted on them
//! covers a quarter of the grid, so harness tests run several times faster on the same code
//! paths (a domain smaller than the grid is a supported case: see `baseline::Domain`).

use crate::merl::grid::valid_mask;
use crate::merl::{cell_coords, grid, CELLS, INVALID_VALUE, N_PHI_D, N_THETA_D, VALUES};
use crate::MerlTable;
use rayon::prelude::*;
use std::sync::{Mutex, OnceLock};

/// Material `i` of the synthetic family: albedo, lobe strength and width vary with `i`.
fn build(i: usize) -> MerlTable {
    let f = i as f32;
    let albedo = [0.2 + 0.07 * f, 0.5 - 0.05 * (f % 4.0), 0.1 + 0.1 * (f % 3.0)];
    let strength = 0.5 + 3.0 * ((f * 0.7).sin().abs());
    let width = 0.05 + 0.04 * (f % 5.0);
    let mask = valid_mask();
    let mut values = vec![INVALID_VALUE; VALUES];
    let (r, rest) = values.split_at_mut(CELLS);
    let (g, b) = rest.split_at_mut(CELLS);
    r.par_chunks_mut(18_000)
        .zip(g.par_chunks_mut(18_000))
        .zip(b.par_chunks_mut(18_000))
        .enumerate()
        .for_each(|(chunk, ((r, g), b))| {
            for (k, cell) in (chunk * 18_000..).take(r.len()).enumerate() {
                if !mask[cell] {
                    continue;
                }
                let (h, d, p) = cell_coords(cell);
                let th = grid::theta_h_of(h) as f32;
                let td = grid::theta_d_of(d) as f32;
                let lobe = strength * (-(th * th) / (width * width)).exp() * (1.0 + 0.2 * td.sin())
                    + 0.01 * (p as f32 / 180.0);
                let rgb = [0, 1, 2]
                    .map(|c| albedo[c] / std::f32::consts::PI + lobe * (1.0 + 0.1 * c as f32));
                (r[k], g[k], b[k]) = (rgb[0], rgb[1], rgb[2]);
            }
        });
    MerlTable::from_values(values).unwrap_or_else(|e| panic!("synthetic table {i}: {e}"))
}

/// Material `i` of the synthetic family (built once, then cloned).
pub fn synthetic_table(i: usize) -> MerlTable {
    static CACHE: OnceLock<Mutex<Vec<Option<MerlTable>>>> = OnceLock::new();
    let cache = CACHE.get_or_init(|| Mutex::new(Vec::new()));
    if let Some(t) = cache.lock().ok().and_then(|c| c.get(i).cloned().flatten()) {
        return t;
    }
    let table = build(i);
    if let Ok(mut c) = cache.lock() {
        if c.len() <= i {
            c.resize(i + 1, None);
        }
        c[i] = Some(table.clone());
    }
    table
}

/// `n` synthetic tables and names.
pub fn synthetic_set(n: usize) -> (Vec<String>, Vec<MerlTable>) {
    ((0..n).map(|i| format!("synthetic-{i}")).collect(), (0..n).map(synthetic_table).collect())
}

/// theta_h indices measured by [`sparse_table`].
pub const SPARSE_THETA_H: usize = 24;

/// [`synthetic_table`] `i` with every cell of theta_h index >= [`SPARSE_THETA_H`] invalid.
pub fn sparse_table(i: usize) -> MerlTable {
    let mut values = synthetic_table(i).into_values();
    let first = SPARSE_THETA_H * N_THETA_D * N_PHI_D;
    for channel in values.chunks_mut(CELLS) {
        channel[first..].fill(INVALID_VALUE);
    }
    MerlTable::from_values(values).unwrap_or_else(|e| panic!("sparse table {i}: {e}"))
}

/// `n` [`sparse_table`]s and names.
pub fn sparse_set(n: usize) -> (Vec<String>, Vec<MerlTable>) {
    ((0..n).map(|i| format!("sparse-{i}")).collect(), (0..n).map(sparse_table).collect())
}
