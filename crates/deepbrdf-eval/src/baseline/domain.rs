//! The cells a linear basis covers: those valid in every training table (and above the horizon
//! on the MERL grid). A BRDF becomes one row of `3 x cells` values, channel-major, cells in MERL
//! order.
//!
//! Invalid (below-horizon) cells carry no measurement, so they are left out of the rows, the
//! basis and every measure. All bundled tables (and MERL's own files) share the grid's mask, so
//! in practice the domain is the grid's 1,090,436-ish valid cells per channel; a table read from
//! a file with extra invalid cells shrinks the domain of a basis fitted on it, and when such a
//! table is *encoded* its missing cells are taken at the basis mean (they add nothing to the
//! coefficients). Decoded tables are valid exactly on the domain.

use crate::error::{EvalError, Result};
use deepbrdf_data::merl::grid::valid_mask;
use deepbrdf_data::merl::CELLS;
use deepbrdf_data::MerlTable;
use rayon::prelude::*;

/// Cells per parallel work item.
const CHUNK: usize = 16 * 1024;

/// Valid cells shared by a set of tables, in increasing MERL order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Domain {
    cells: Vec<u32>,
}

impl Domain {
    /// Cells valid in all `tables` and on the grid ([`deepbrdf_data::merl::grid::cell_is_valid`]).
    pub fn common(tables: &[&MerlTable]) -> Result<Self> {
        let grid = valid_mask();
        let cells: Vec<u32> = grid
            .par_chunks(CHUNK)
            .enumerate()
            .flat_map_iter(|(b, chunk)| {
                (b * CHUNK..).zip(chunk).filter_map(|(c, &on_grid)| {
                    (on_grid && tables.iter().all(|t| t.is_valid(c))).then_some(c as u32)
                })
            })
            .collect();
        if cells.is_empty() {
            return Err(EvalError::Invalid("the tables share no valid cell".into()));
        }
        Ok(Self { cells })
    }

    /// A domain from stored cell indices (an artifact): strictly increasing, below [`CELLS`].
    pub fn from_cells(cells: Vec<u32>) -> Result<Self> {
        if cells.is_empty() {
            return Err(EvalError::Invalid("an empty domain".into()));
        }
        if cells.windows(2).any(|w| w[0] >= w[1])
            || cells.last().is_some_and(|&c| c as usize >= CELLS)
        {
            return Err(EvalError::Invalid("domain cells are not increasing cell indices".into()));
        }
        Ok(Self { cells })
    }

    /// The cells (flat MERL indices within a channel).
    pub fn cells(&self) -> &[u32] {
        &self.cells
    }

    /// Length of a row: three channels of every cell.
    pub fn dim(&self) -> usize {
        3 * self.cells.len()
    }

    /// Position in a row of channel `c` of the `m`-th domain cell.
    #[inline]
    pub fn row_index(&self, c: usize, m: usize) -> usize {
        c * self.cells.len() + m
    }

    /// The range of domain positions `m` whose cells lie in `cells` (a range of cell indices).
    pub fn positions_in(&self, cells: std::ops::Range<usize>) -> std::ops::Range<usize> {
        let lo = self.cells.partition_point(|&c| (c as usize) < cells.start);
        let hi = self.cells.partition_point(|&c| (c as usize) < cells.end);
        lo..hi
    }
}
