//! The value mapping applied before PCA: the logarithm of traditional PCA, or IPCA's
//! cosine-weighted log-relative mapping (Nielsen et al. 2015). Rows are in [`Domain`] order.

use super::domain::Domain;
use crate::error::{EvalError, Result};
use crate::{ipca, pca};
use deepbrdf_data::merl::{CELLS, INVALID_VALUE, VALUES};
use deepbrdf_data::MerlTable;
use rayon::prelude::*;

/// Values per parallel work item; divides [`CELLS`] (1,458,000 = 81 x 18,000).
const CHUNK: usize = 18_000;

/// Which mapping a baseline uses, before fitting (IPCA's reference comes from the training set).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MappingKind {
    /// `ln(rho + LOG_EPSILON)`: traditional PCA.
    Log,
    /// `ln((rho cos_i cos_o + eps) / (rho_ref cos_i cos_o + eps))`: IPCA.
    LogRelative,
}

/// A fitted mapping.
#[derive(Clone, Debug, PartialEq)]
pub enum Mapping {
    /// Traditional PCA's logarithm ([`pca::log_map`]).
    Log,
    /// IPCA's log-relative mapping ([`ipca::cosine_log_relative`]).
    LogRelative {
        /// rho_ref in row order (the per-value median of the training tables).
        reference: Vec<f32>,
        /// cos(theta_i) cos(theta_o) of each domain cell.
        cos_weight: Vec<f32>,
        /// eps of the mapping: [`ipca::EPSILON`] (IPCA's and every saved basis'), or another
        /// for a separated specular part ([`Mapping::with_epsilon`]).
        epsilon: f64,
    },
}

impl Mapping {
    /// This mapping's kind.
    pub fn kind(&self) -> MappingKind {
        match self {
            Self::Log => MappingKind::Log,
            Self::LogRelative { .. } => MappingKind::LogRelative,
        }
    }

    /// IPCA's mapping over `domain`, with `reference` the full-table (VALUES long) median.
    pub fn log_relative(domain: &Domain, reference: &[f32]) -> Result<Self> {
        if reference.len() != VALUES {
            return Err(EvalError::Invalid(format!(
                "a reference table has {VALUES} values, got {}",
                reference.len()
            )));
        }
        let n = domain.cells().len();
        let mut row = vec![0f32; domain.dim()];
        for c in 0..3 {
            for (m, &cell) in domain.cells().iter().enumerate() {
                row[domain.row_index(c, m)] = reference[c * CELLS + cell as usize];
            }
        }
        let weights = deepbrdf_data::merl::grid::cos_weights();
        let cos_weight = domain.cells().iter().map(|&c| weights[c as usize]).collect::<Vec<_>>();
        debug_assert_eq!(cos_weight.len(), n);
        Self::log_relative_from_parts(domain, row, cos_weight)
    }

    /// IPCA's mapping from a row-ordered reference and per-cell weights (an artifact).
    pub fn log_relative_from_parts(
        domain: &Domain,
        reference: Vec<f32>,
        cos_weight: Vec<f32>,
    ) -> Result<Self> {
        if reference.len() != domain.dim() || cos_weight.len() != domain.cells().len() {
            return Err(EvalError::Invalid("IPCA reference does not match its domain".into()));
        }
        if let Some(i) = reference.iter().position(|r| !(r.is_finite() && *r >= 0.0)) {
            return Err(EvalError::Invalid(format!(
                "IPCA reference value {i} is {}",
                reference[i]
            )));
        }
        if cos_weight.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
            return Err(EvalError::Invalid("IPCA cosine weight not positive on the domain".into()));
        }
        Ok(Self::LogRelative { reference, cos_weight, epsilon: ipca::EPSILON })
    }

    /// The same mapping with `eps` in place of IPCA's (a log-relative mapping; the logarithm
    /// has none). `eps` must be positive and finite.
    pub fn with_epsilon(self, eps: f64) -> Result<Self> {
        if !(eps.is_finite() && eps > 0.0) {
            return Err(EvalError::Invalid(format!(
                "the mapping's eps must be positive, got {eps}"
            )));
        }
        Ok(match self {
            Self::LogRelative { reference, cos_weight, .. } => {
                Self::LogRelative { reference, cos_weight, epsilon: eps }
            }
            Self::Log => Self::Log,
        })
    }

    /// Maps `table` to a row over `domain`. A domain cell that is invalid in `table` gets NaN
    /// (the codec replaces it with the basis mean).
    pub fn forward(&self, domain: &Domain, table: &MerlTable) -> Vec<f32> {
        self.forward_less(domain, table, [0.0; 3])
    }

    /// [`Mapping::forward`] of what is left of `table` once `less[c]` is taken off every value of
    /// channel c: the specular part of a BRDF whose diffuse part is `less`
    /// ([`crate::separation`]). A remainder below zero is floored as the mappings say.
    pub fn forward_less(&self, domain: &Domain, table: &MerlTable, less: [f64; 3]) -> Vec<f32> {
        let n = domain.cells().len();
        let values = table.values();
        let mut row = vec![0f32; domain.dim()];
        for (c, channel) in row.chunks_mut(n).enumerate() {
            channel.par_chunks_mut(CHUNK).enumerate().for_each(|(b, out)| {
                let start = b * CHUNK;
                let cells = &domain.cells()[start..start + out.len()];
                for ((o, &cell), m) in out.iter_mut().zip(cells).zip(start..) {
                    let cell = cell as usize;
                    if !table.is_valid(cell) {
                        *o = f32::NAN;
                        continue;
                    }
                    let rho = f64::from(values[c * CELLS + cell]) - less[c];
                    *o = match self {
                        Self::Log => pca::log_map(rho),
                        Self::LogRelative { reference, cos_weight, epsilon } => {
                            ipca::cosine_log_relative_eps(
                                rho,
                                f64::from(reference[c * n + m]),
                                f64::from(cos_weight[m]),
                                *epsilon,
                            )
                        }
                    } as f32;
                }
            });
        }
        row
    }

    /// Inverse of [`Mapping::forward`]: a full table, valid exactly on `domain`, reflectance
    /// clamped to `[0, f32::MAX]` (a truncated basis can decode below zero).
    pub fn inverse(&self, domain: &Domain, row: &[f32]) -> Result<MerlTable> {
        self.inverse_plus(domain, row, [0.0; 3])
    }

    /// [`Mapping::inverse`] with `plus[c]` added to every value of channel c before the clamp:
    /// a decoded specular part plus its diffuse part ([`crate::separation`]).
    pub fn inverse_plus(&self, domain: &Domain, row: &[f32], plus: [f64; 3]) -> Result<MerlTable> {
        if row.len() != domain.dim() {
            return Err(EvalError::Invalid(format!(
                "row of length {} for a domain of {} values",
                row.len(),
                domain.dim()
            )));
        }
        let n = domain.cells().len();
        let mut values = vec![INVALID_VALUE; VALUES];
        values.par_chunks_mut(CHUNK).enumerate().for_each(|(b, out)| {
            // Chunks divide CELLS, so each lies within one channel.
            let (c, first) = ((b * CHUNK) / CELLS, (b * CHUNK) % CELLS);
            let positions = domain.positions_in(first..first + out.len());
            let cells = &domain.cells()[positions.clone()];
            for (&cell, m) in cells.iter().zip(positions) {
                let y = f64::from(row[c * n + m]);
                let rho = match self {
                    Self::Log => pca::log_unmap(y),
                    Self::LogRelative { reference, cos_weight, epsilon } => {
                        ipca::cosine_log_relative_inverse_eps(
                            y,
                            f64::from(reference[c * n + m]),
                            f64::from(cos_weight[m]),
                            *epsilon,
                        )
                    }
                };
                out[cell as usize - first] = clamp_reflectance(rho + plus[c]);
            }
        });
        Ok(MerlTable::from_values(values)?)
    }
}

/// A decoded reflectance as a valid table value: NaN and negatives to 0, overflow to f32::MAX.
fn clamp_reflectance(rho: f64) -> f32 {
    if rho.is_nan() || rho <= 0.0 {
        0.0
    } else {
        rho.min(f64::from(f32::MAX)) as f32
    }
}
