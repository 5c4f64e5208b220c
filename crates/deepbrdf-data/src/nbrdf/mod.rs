//! Neural BRDF networks (Sztrajman et al., CGF 2021): the data source for MERL-like tables on
//! machines without the MERL database. `network` parses and evaluates one network, `tabulate`
//! samples it onto the MERL grid, `pack` is the compact binary form the crate bundles.
pub mod network;
pub mod pack;
pub mod tabulate;

pub use network::{input_vector, Network, HIDDEN, INPUTS, OUTPUTS, PARAMETERS};
pub use pack::{pack, pack_json_folder, read_json_folder, unpack};
pub use tabulate::{tabulate, TABULATOR_VERSION};
