//! The MERL BRDF format (Matusik et al. 2003): grid, table.
pub mod grid;
pub mod table;

pub use table::{
    cell_coords, cell_index, MerlTable, CELLS, INVALID_VALUE, MERL_SCALE, N_PHI_D, N_THETA_D,
    N_THETA_H, VALUES,
};
