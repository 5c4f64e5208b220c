//! The MERL BRDF format (Matusik et al. 2003): grid, table, file I/O, Rusinkiewicz coordinates,
//! lookup.
pub mod coords;
pub mod grid;
pub mod io;
pub mod lookup;
pub mod table;

pub use grid::{cell_coords, cell_index, CELLS, N_PHI_D, N_THETA_D, N_THETA_H, VALUES};
pub use io::{merl_bytes, read_merl, write_merl, MerlFile};
pub use table::{MerlTable, INVALID_VALUE, MERL_SCALE};
