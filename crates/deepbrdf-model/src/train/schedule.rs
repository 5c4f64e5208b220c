//! The learning-rate schedule: a half cosine from the initial rate to a final fraction of it
//! over all steps of a run (constant when the fraction is 1, the paper's setting), scaled by a
//! linear warm-up over the first epochs when the run has one.

use super::config::LoopConfig;

impl LoopConfig {
    /// The learning rate of step `step` (0-based) of `total`.
    pub fn learning_rate_at(&self, step: usize, total: usize) -> f64 {
        let end = self.learning_rate * self.final_lr_factor;
        let t = if total <= 1 { 0.0 } else { step as f64 / (total - 1) as f64 };
        let cosine =
            end + 0.5 * (self.learning_rate - end) * (1.0 + (std::f64::consts::PI * t).cos());
        let warmup = self.warmup_epochs * total as f64 / self.epochs.max(1) as f64;
        if (step as f64) + 1.0 < warmup {
            cosine * (step as f64 + 1.0) / warmup
        } else {
            cosine
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::config::adam;
    use super::*;

    #[test]
    fn the_learning_rate_decays_along_a_half_cosine() {
        let c = LoopConfig::new(adam()).with_learning_rate(1.0).with_final_lr_factor(0.1);
        assert!((c.learning_rate_at(0, 11) - 1.0).abs() < 1e-12);
        assert!((c.learning_rate_at(5, 11) - 0.55).abs() < 1e-12);
        assert!((c.learning_rate_at(10, 11) - 0.1).abs() < 1e-12);
        let constant = c.with_final_lr_factor(1.0);
        assert_eq!(constant.learning_rate_at(3, 11), 1.0);
        assert_eq!(constant.learning_rate_at(0, 1), 1.0);
    }

    #[test]
    fn a_warm_up_rises_linearly_then_joins_the_cosine() {
        // 10 epochs of 10 steps, 2 epochs of warm-up: 20 steps rising to the cosine's rate.
        let c = LoopConfig::new(adam())
            .with_learning_rate(1.0)
            .with_final_lr_factor(0.1)
            .with_epochs(10)
            .with_warmup_epochs(2.0);
        let plain = c.clone().with_warmup_epochs(0.0);
        assert!((c.learning_rate_at(0, 100) - plain.learning_rate_at(0, 100) / 20.0).abs() < 1e-12);
        assert!((c.learning_rate_at(9, 100) - plain.learning_rate_at(9, 100) / 2.0).abs() < 1e-12);
        for step in 19..100 {
            assert_eq!(c.learning_rate_at(step, 100), plain.learning_rate_at(step, 100));
        }
        assert!(c.clone().with_warmup_epochs(11.0).validate().is_err());
        assert!(c.with_warmup_epochs(-1.0).validate().is_err());
    }
}
