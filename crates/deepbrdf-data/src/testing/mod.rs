//! Tables for tests in this crate and the others: analytic BRDFs tabulated on the MERL grid
//! ([`analytic`]) and a small synthetic family of materials ([`family`]).
pub mod analytic;
pub mod family;
pub mod mutate;

pub use analytic::*;
pub use family::{sparse_set, sparse_table, synthetic_set, synthetic_table, SPARSE_THETA_H};
