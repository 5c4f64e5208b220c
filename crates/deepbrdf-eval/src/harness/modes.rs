//! Evaluation modes: which materials a codec is fitted on and which it is evaluated on.

use crate::error::{EvalError, Result};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::fmt;
use std::str::FromStr;

/// How training and evaluation materials are chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Fit on all materials, evaluate on the same ones (the paper's Fig. 3).
    InSample,
    /// `folds`-fold cross-validation: each material is evaluated exactly once, by a codec fitted
    /// on the other folds (seeded split).
    KFold { folds: usize },
    /// Fit on one collection, evaluate on others (the paper's Fig. 9: MERL -> EPFL/RGL, Nielsen).
    Generalize,
}

impl FromStr for Mode {
    type Err = EvalError;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "in-sample" => Ok(Self::InSample),
            "generalize" => Ok(Self::Generalize),
            _ => {
                let folds = s
                    .strip_prefix("kfold:")
                    .and_then(|n| n.parse::<usize>().ok())
                    .ok_or_else(|| {
                        EvalError::Invalid(format!(
                            "unknown mode '{s}' (in-sample, kfold:N, generalize)"
                        ))
                    })?;
                if folds < 2 {
                    return Err(EvalError::Invalid(format!(
                        "kfold needs at least 2 folds, got {folds}"
                    )));
                }
                Ok(Self::KFold { folds })
            }
        }
    }
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InSample => f.write_str("in-sample"),
            Self::KFold { folds } => write!(f, "kfold:{folds}"),
            Self::Generalize => f.write_str("generalize"),
        }
    }
}

/// One fit/evaluate round: indices into the training set and into the evaluation set (the same
/// dataset except in [`Mode::Generalize`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Fold {
    pub index: usize,
    pub train: Vec<usize>,
    pub test: Vec<usize>,
}

impl Mode {
    /// The folds of this mode for `n_train` training materials and `n_eval` evaluation
    /// materials (ignored except in generalize mode). Deterministic in `seed`.
    pub fn folds(&self, n_train: usize, n_eval: usize, seed: u64) -> Result<Vec<Fold>> {
        let all: Vec<usize> = (0..n_train).collect();
        match *self {
            Self::InSample => Ok(vec![Fold { index: 0, train: all.clone(), test: all }]),
            Self::Generalize => {
                if n_eval == 0 {
                    return Err(EvalError::Invalid(
                        "generalize mode has no evaluation materials".into(),
                    ));
                }
                Ok(vec![Fold { index: 0, train: all, test: (0..n_eval).collect() }])
            }
            Self::KFold { folds } => {
                if n_train < folds {
                    return Err(EvalError::Invalid(format!(
                        "{folds}-fold cross-validation needs at least {folds} materials, got {n_train}"
                    )));
                }
                let mut order = all;
                order.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
                Ok((0..folds)
                    .map(|f| {
                        let (lo, hi) = (f * n_train / folds, (f + 1) * n_train / folds);
                        let mut test = order[lo..hi].to_vec();
                        let mut train: Vec<usize> =
                            order[..lo].iter().chain(&order[hi..]).copied().collect();
                        test.sort_unstable();
                        train.sort_unstable();
                        Fold { index: f, train, test }
                    })
                    .collect())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_parse_and_print() {
        for s in ["in-sample", "kfold:5", "generalize"] {
            assert_eq!(s.parse::<Mode>().unwrap().to_string(), s);
        }
        for bad in ["kfold", "kfold:1", "kfold:x", "insample", ""] {
            assert!(bad.parse::<Mode>().is_err(), "{bad}");
        }
    }

    #[test]
    fn kfold_partitions_and_never_tests_a_training_material() {
        let n = 23;
        let folds = Mode::KFold { folds: 5 }.folds(n, 0, 9).unwrap();
        assert_eq!(folds.len(), 5);
        let mut seen = vec![0; n];
        for f in &folds {
            assert!(f.test.iter().all(|t| !f.train.contains(t)), "fold {f:?}");
            assert_eq!(f.train.len() + f.test.len(), n);
            assert!(f.test.len() >= n / 5 && f.test.len() <= n / 5 + 1);
            f.test.iter().for_each(|&t| seen[t] += 1);
        }
        assert!(seen.iter().all(|&s| s == 1), "each material tested once: {seen:?}");
        // Deterministic in the seed, different for another seed.
        assert_eq!(folds, Mode::KFold { folds: 5 }.folds(n, 0, 9).unwrap());
        assert_ne!(folds, Mode::KFold { folds: 5 }.folds(n, 0, 10).unwrap());
        assert!(Mode::KFold { folds: 5 }.folds(4, 0, 9).is_err());
    }
}
