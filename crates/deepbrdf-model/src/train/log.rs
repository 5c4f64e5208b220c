//! The per-epoch training log: one [`EpochRecord`] per finished epoch, kept in the checkpoint
//! and written as CSV (`train_log.csv`) after every epoch. The CSV holds what the seed
//! determines (epoch, loss, learning rate), so two runs with the same seed write the same
//! bytes; the seconds each epoch took stay in the checkpoint.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::artifact::files::write_atomic;

/// File name of the per-epoch CSV log inside a training directory.
pub const LOG_FILE: &str = "train_log.csv";

/// One row of the training log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpochRecord {
    /// Epoch number, from 1.
    pub epoch: usize,
    /// Mean over the epoch's batches (weighted by batch size) of the network's loss.
    pub loss: f64,
    /// Learning rate of the epoch's last step.
    pub learning_rate: f64,
    /// Seconds the epoch took (summed over resumed pieces).
    pub seconds: f64,
}

/// The log as CSV: `epoch,loss,learning_rate`, losses and rates to 7 significant digits.
pub fn log_csv(log: &[EpochRecord]) -> String {
    let mut csv = String::from("epoch,loss,learning_rate\n");
    for r in log {
        csv.push_str(&format!("{},{:.6e},{:.6e}\n", r.epoch, r.loss, r.learning_rate));
    }
    csv
}

/// Writes [`log_csv`] to `path` atomically.
pub(super) fn write_log(path: &Path, log: &[EpochRecord]) -> crate::error::Result<()> {
    write_atomic(path, &[log_csv(log).as_bytes()])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_csv_has_a_header_and_one_row_per_epoch() {
        let log = [
            EpochRecord { epoch: 1, loss: 0.5, learning_rate: 1e-3, seconds: 1.23456 },
            EpochRecord { epoch: 2, loss: 1.0 / 3.0, learning_rate: 5e-5, seconds: 0.0 },
        ];
        assert_eq!(
            log_csv(&log),
            "epoch,loss,learning_rate\n1,5.000000e-1,1.000000e-3\n2,3.333333e-1,5.000000e-5\n"
        );
    }
}
